"""A match that did not play is a failure with its cause, charged only to a team that caused
it, and said in the status and the mail; a team file that fails its pre-flight check never
becomes the current version."""

from __future__ import annotations

import json
import time
from collections.abc import Callable
from email import message_from_bytes
from pathlib import Path
from types import SimpleNamespace
from typing import Any

import pytest

from cluster.fake import FakePool
from service import Settings, notify
from tests.integration.service.harness import Served
from tests.unit.service.conftest import team_doc, wait_for_status
from tests.unit.service.test_submissions import handle_of, setup_team

NOT_PLAYED = {"status": "failed", "failure_class": "not_played",
              "cause": "the match did not play (0 s of PLAYING): the league's timing: READY..."}
ABSENT = {"status": "failed", "failure_class": "team_absent", "team": "red",
          "cause": "the match did not play (0 s of PLAYING): no robot of red ever connected"}


def _finished(served: Served, http: Any, pool: FakePool, report: dict[str, Any]
              ) -> dict[str, Any]:
    sid = http.post("/v1/submissions", json={}).json()["id"]
    wait_for_status(http, sid, lambda b: b["state"] == "running")
    pool.finish(handle_of(served, sid), report)
    return wait_for_status(http, sid, lambda b: b["state"] == "failed")


def test_a_match_without_play_is_failed_and_charged_only_for_the_teams_cause(
        start: Callable[..., Served], token: Callable[..., str], pool: FakePool) -> None:
    served = start()
    with setup_team(served, token("Alpha"), "Alpha") as http:
        league = _finished(served, http, pool, NOT_PLAYED)
        assert league["failure_class"] == "not_played" and league["failure_side"] == "league"
        assert league["charged"] is False and "league's timing" in league["cause"]
        report = http.get(f"/v1/submissions/{league['id']}/report").json()
        assert report["match_report"]["failure_class"] == "not_played"
        assert report["backend_error"] is True
        absent = _finished(served, http, pool, ABSENT)
        assert absent["failure_side"] == "team" and absent["charged"] is True
        assert "no robot of red ever connected" in absent["cause"]


def test_the_mail_says_score_outcome_and_links_to_pages(
        monkeypatch: pytest.MonkeyPatch) -> None:
    from service.db import Submission

    settings = Settings(public_url="https://league.example.org/")
    row = Submission(id="sub_1", state="done", opponent="stub", match_id="m", charged=True,
                     failure_class=None, failure_side=None, cause=None)
    from dataclasses import replace

    from cluster.fake import fake_results
    from service.results import MatchSummary

    results = MatchSummary.of(replace(fake_results("m", None), score={"red": 2, "blue": 1}),
                              {"red": "Alpha", "blue": "stub"})
    results = replace(results, playing_s=50.0)
    data = notify.payload(row, "submission.finished", settings, results)
    assert data["submission"]["outcome"] == "won"
    sent: list[bytes] = []

    class Smtp:  # the SMTP server of the mail test is in the real-match test
        def __init__(self, *_: Any, **__: Any) -> None:
            pass

        def __enter__(self) -> Smtp:
            return self

        def __exit__(self, *_: Any) -> None:
            pass

        def send_message(self, message: Any) -> None:
            sent.append(message.as_bytes())

    monkeypatch.setattr(notify.smtplib, "SMTP", Smtp)
    notify.send_mail(settings, to="a@example.org", event="submission.finished",
                     data=json.loads(json.dumps(data)))
    text = str(message_from_bytes(sent[0]).get_payload())
    assert "score:   you (red) 2 : 1 stub" in text and "outcome: won" in text
    assert "https://league.example.org/watch/replay/sub_1" in text
    assert "https://league.example.org/watch/ladder" in text
    row.state, row.failure_class, row.failure_side = "failed", "not_played", "league"
    assert notify.outcome_of(row, results) == \
        "not counted: not_played on the league's side (not charged)"


def test_a_team_file_that_fails_its_preflight_never_becomes_current(
        start: Callable[..., Served], token: Callable[..., str]) -> None:
    served = start()
    with setup_team(served, token("Alpha"), "Alpha") as http:
        broken = team_doc("Alpha", image="127.0.0.1:1/bad/image")
        assert http.put("/v1/team/files/team_config", json=broken).status_code == 201
        refused = http.post("/v1/submissions", json={})
        assert refused.status_code == 422 and refused.json()["stage"] == "pull"
        versions = {v["version"]: v for v in http.get("/v1/team/files/team_config").json()}
        assert versions[1]["valid"] is True and versions[2]["valid"] is False
        assert "pre-flight check failed at pull" in versions[2]["problems"][-1]["text"]
        again = http.post("/v1/submissions", json={})  # the current version: 1
        assert again.status_code == 201, again.text


def test_a_render_under_way_ends_with_the_service_and_its_partial_video_is_not_served(
        tmp_path: Path, settings: Settings) -> None:
    from service.aftermatch import PARTIAL_VIDEO_FILE, AfterMatch
    from service.routers.submissions import _listing

    renderer = tmp_path / "renderer.sh"  # stands for `python -m simulator render ... -o FILE`
    renderer.write_text('#!/bin/sh\necho partial > "$6"\nexec sleep 60\n')
    renderer.chmod(0o755)
    out, work = tmp_path / "out", tmp_path / "work"
    (out / "public").mkdir(parents=True)
    (out / "public" / "replay.hlvsrec").write_bytes(b"replay")
    after = AfterMatch(settings=settings, sessions=None, pool=None, sealer=None,  # type: ignore[arg-type]
                       python=str(renderer))
    after._start(SimpleNamespace(id="sub_1", match_id="m1"), out, work, 1)  # type: ignore[arg-type]
    render = after._render
    assert render is not None
    deadline = time.monotonic() + 10
    while not (out / "public" / PARTIAL_VIDEO_FILE).is_file():
        assert time.monotonic() < deadline
        time.sleep(0.05)
    assert _listing(out / "public") == ["replay.hlvsrec"]
    after.stop()
    assert render.process.poll() is not None  # no render outlives the service
    assert not (out / "public" / PARTIAL_VIDEO_FILE).exists()
    assert json.loads((work / "render.json").read_text())["renders"] == 0
