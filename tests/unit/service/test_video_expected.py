"""A pending video says when it is expected: the render under way from its start, the others
after it in their order, each taking its match's length times the measured render ratio."""

from __future__ import annotations

from datetime import UTC, datetime

from service.aftermatch import pending_details

NOW = datetime(2026, 5, 1, 12, 0, 0, tzinfo=UTC)


def test_the_render_under_way_then_the_queue_in_order() -> None:
    details = pending_details([("sub_a", 120.0), ("sub_b", 120.0), ("sub_c", 60.0)], now=NOW,
                              rendering_id="sub_a", rendering_elapsed_s=300.0,
                              render_per_match_s=5.0)
    assert details == {
        "sub_a": "rendering since 11:55 UTC; expected by about 12:05 UTC",
        "sub_b": "waiting for the render (1 ahead of it); expected by about 12:15 UTC",
        "sub_c": "waiting for the render (2 ahead of it); expected by about 12:20 UTC",
    }


def test_an_overdue_render_is_expected_a_minute_on_and_the_next_waits_for_it() -> None:
    details = pending_details([("sub_a", 60.0), ("sub_b", 30.0)], now=NOW, rendering_id="sub_a",
                              rendering_elapsed_s=900.0, render_per_match_s=2.0)
    assert details["sub_a"] == "rendering since 11:45 UTC; expected by about 12:01 UTC"
    assert details["sub_b"] == ("waiting for the render (1 ahead of it); expected by about "
                                "12:02 UTC")
    alone = pending_details([("sub_b", 30.0)], now=NOW, rendering_id=None,
                            rendering_elapsed_s=0.0, render_per_match_s=2.0)
    assert alone == {"sub_b": "waiting for the render (next); expected by about 12:01 UTC"}


def test_the_after_match_thread_writes_the_expectation_into_each_pending_video() -> None:
    from datetime import timedelta

    from service import Settings
    from service.aftermatch import AfterMatch
    from service.db import Submission

    start = datetime(2026, 5, 1, 11, 0, 0)  # the database's naive UTC
    rows = [Submission(id=f"sub_{n}", started_at=start, finished_at=start + timedelta(seconds=60),
                       video_state="pending", video_detail="waiting for the render")
            for n in range(2)]
    after = AfterMatch(settings=Settings(), sessions=None, pool=None, sealer=None)  # type: ignore[arg-type]
    after._expect(rows)
    assert [r.video_detail.split(";")[0] for r in rows] == [
        "waiting for the render (next)", "waiting for the render (1 ahead of it)"]
    assert all("expected by about" in r.video_detail and r.video_detail.endswith(" UTC")
               for r in rows)
