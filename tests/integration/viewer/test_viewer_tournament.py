"""The operator's live overview of a tournament (``/watch/tournament`` in a real ``hlvs serve``,
Chromium): every match with its state, score or live clock, log states and links; the knockout
bracket after a shoot-out; the replay with the teams' names; auto-refresh; operators only."""

from __future__ import annotations

import shutil
import threading
import time
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import httpx
import pytest

from testkit.sftp import free_port
from testkit.specs import match_spec
from tests.integration.service.harness import Served
from tests.integration.viewer.conftest import screenshot
from tests.unit.schedule import fake_services
from tests.unit.schedule.test_schedule import COMPRESSED, FAKE, write_schedule
from tests.unit.schedule.test_tournament_day import queue_set
from tests.unit.viewer.replays import record_match
from tournament import Ledger, ScheduledMatchState, run_schedule

pytestmark = pytest.mark.browser
S = ScheduledMatchState
LIVE = {"state": "PLAYING", "secondary_state": "NORMAL", "half": 2, "secs_remaining": 451,
        "score": {"red": 2, "blue": 1}}


@pytest.fixture
def cup(tmp_path: Path) -> Iterator[Path]:
    """A knockout of four teams (the first semi-final drawn, decided by a shoot-out; delta's
    log server down) and a round-robin match left running, as the scheduler would have it."""
    fake_services.DRAWN.add("ko-r1-1")
    fake_services.DEAD_TEAMS.add("delta")
    path = write_schedule(
        tmp_path,
        COMPRESSED.replace("retry_s: 0.2", "retry_s: 0.2, delivery_attempts: 1")
        + "fixtures:\n  knockout: {seeds: [alpha, bravo, charlie, delta], first_stream: '+4s',"
        " interval_s: 1.0, stream_length_s: 0.3}\n"
        "matches:\n  - {id: show, red: alpha, blue: charlie, stream_start: '+2h'}\n",
    )
    state = tmp_path / "state.sqlite"
    stop = threading.Event()
    thread = threading.Thread(target=run_schedule, args=(path, state),
                              kwargs={"services": FAKE, "poll_s": 0.1, "stop": stop})
    thread.start()
    try:
        deadline = time.monotonic() + 60
        while not (state.exists() and any(r.id == "ko-r2-1" and r.state.final
                                          for r in Ledger(state).rows())):
            assert time.monotonic() < deadline, "the knockout did not finish"
            time.sleep(0.1)
    finally:
        stop.set()
        thread.join(timeout=30)
        fake_services.DRAWN.clear()
        fake_services.DEAD_TEAMS.clear()
    queue_set(tmp_path / "out" / "log-store", "ko-r1-2", "delta")  # delta's set waits
    ledger = Ledger(state)
    assert ledger.transition("show", (S.PLANNED,), S.PLAYING, count_attempt=True)
    folder = tmp_path / "out" / "show" / "match" / "simulator"
    folder.mkdir(parents=True)
    match_spec(match_id="show", seed=1, ports={}, addresses={},
               telemetry=f"tcp/127.0.0.1:{free_port()}").write(folder / "match_spec.json")
    final = tmp_path / "out" / "ko-r2-1" / "match" / "public"  # where hlvs match leaves it
    final.mkdir(parents=True)
    shutil.copy(record_match(tmp_path / "recorded"), final / "replay.hlvsrec")
    yield state


def _rows(page: Any, testid: str) -> dict[str, list[str]]:
    page.wait_for_selector(f"[data-testid={testid}] tr")
    rows: list[list[str]] = page.locator(f"[data-testid={testid}] tr").evaluate_all(
        "rows => rows.slice(1).map(r => Array.from(r.cells).map(c => c.innerText))")
    return {row[0]: row for row in rows}


def test_operator_overview_of_a_tournament(
    start: Callable[..., Served], token: Callable[..., str], page: Any, cup: Path,
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    seen: list[Path] = []

    def snapshot(folder: Path) -> dict[str, Any]:
        seen.append(folder)
        return LIVE

    monkeypatch.setattr("viewer.tournament_pages.snapshot", snapshot)
    served = start(schedule_state=str(cup))
    operator = token(operator=True)
    team = token("A1")
    answer = httpx.get(f"{served.url}/v1/operator/tournament",
                       headers={"Authorization": f"Bearer {team}"})
    assert answer.status_code == 401 and "operator token" in answer.text, answer.text

    page.goto(f"{served.url}/watch/")
    page.locator("[data-testid=token]").fill(operator)
    page.locator("[data-testid=sign-in]").click()
    page.wait_for_selector("[data-testid=who]")  # signed in for this browser session
    page.goto(f"{served.url}/watch/tournament")
    assert page.locator("[data-testid=tournament-name]").inner_text() == "test cup"
    rows = _rows(page, "tournament-matches")
    ledger = Ledger(cup)
    semi = ledger.row("ko-r1-1")
    assert semi.result is not None and semi.result["shootout"] is not None
    # the drawn semi-final: played, decided by the shoot-out, every log delivered
    assert rows["ko-r1-1"][6] == "DELIVERED" and rows["ko-r1-1"][7] == "played, logs delivered"
    assert rows["ko-r1-1"][8].startswith("1-1 (shoot-out ")
    assert rows["ko-r1-1"][9].split() == ["alpha:", "delivered", "bravo:", "delivered"]
    # the other: delta's log server is down, so it is played but its logs are not delivered
    assert rows["ko-r1-2"][6] == "LOGS_FAILED" and rows["ko-r1-2"][7] == "played"
    assert "charlie: delivered" in rows["ko-r1-2"][9]
    assert "delta: failed - unreachable: connection refused" in rows["ko-r1-2"][9]
    # the running match: its clock and score, a live link with the teams' names
    assert rows["show"][6] == "PLAYING" and rows["show"][8] == "2-1 PLAYING 2nd half 07:31"
    assert page.locator("[data-testid=live-show]").get_attribute("href") == (
        "/watch/tournament/live/show?red=alpha&blue=charlie")
    assert seen == [cup.parent / "out" / "show" / "match"]
    # the scheduler stopped with "show" left PLAYING: the page says nobody runs it
    assert page.locator("[data-testid=warnings]").inner_text().startswith(
        "scheduler not running since ")
    # the bracket: the shoot-out's winner is in the final
    final = ledger.row("ko-r2-1")
    winner = semi.result["winner_team"]
    assert winner in (final.red, final.blue)
    first_round = page.locator("[data-testid=round-1] .tie").all_inner_texts()
    final_round = page.locator("[data-testid=round-2] .tie").all_inner_texts()
    assert len(first_round) == 2 and len(final_round) == 1 and winner in final_round[0]
    screenshot(page, "tournament-overview")

    # auto-refresh: a match that ends shows up without reloading the page
    before = page.locator("[data-testid=tournament-updated]").inner_text()
    ledger.transition("show", (S.PLAYING,), S.ABORTED, note="aborted by the operator: test")
    page.wait_for_function(
        "Array.from(document.querySelectorAll('[data-testid=tournament-matches] tr'))"
        ".some(r => r.cells[0].innerText === 'show' && r.cells[6].innerText === 'ABORTED')",
        timeout=20_000)
    assert page.locator("[data-testid=tournament-updated]").inner_text() != before

    # the final's replay in the 3D viewer, with the teams' names on the scoreboard
    page.locator("[data-testid=replay-ko-r2-1]").click()
    page.wait_for_function("window.hlvsViewer && window.hlvsViewer.ready", timeout=30_000)
    assert page.locator("[data-testid=team-red]").inner_text() == final.red
    assert page.locator("[data-testid=team-blue]").inner_text() == final.blue
    screenshot(page, "tournament-replay")
    for who, status in ((None, 401), (team, 401), (operator, 200)):
        headers = {"Authorization": f"Bearer {who}"} if who else {}
        answer = httpx.get(f"{served.url}/api/tournament/replays/ko-r2-1/meta", headers=headers)
        assert answer.status_code == status, answer.text
