"""The front end inside a real ``hlvs serve`` (fake match pool, SQLite) in Chromium: the queue
with positions, expected starts and reasons, a team's submissions with the replay of a finished
match in the 3D viewer, the schedule and standings, the pool; other teams' replays are hidden."""

from __future__ import annotations

import shutil
from collections.abc import Callable
from pathlib import Path
from typing import Any

import httpx
import pytest

from cluster.fake import FakePool
from orchestrator.config.schedule import load_schedule
from tests.integration.service.harness import Served
from tests.integration.viewer.conftest import screenshot
from tests.unit.schedule.test_schedule import COMPRESSED, FAKE, write_schedule
from tests.unit.service.conftest import wait_for_status
from tests.unit.service.test_submissions import handle_of, setup_team
from tests.unit.viewer.replays import record_match
from tournament import Ledger, run_schedule, standings

pytestmark = pytest.mark.browser


def _use_token(page: Any, base: str, secret: str, path: str) -> None:
    page.goto(f"{base}/watch/")
    page.locator("[data-testid=token]").fill(secret)
    page.locator("[data-testid=token-save]").click()
    page.goto(f"{base}{path}")


def _rows(page: Any, testid: str) -> list[list[str]]:
    page.wait_for_selector(f"[data-testid={testid}] tr")
    rows: list[list[str]] = page.locator(f"[data-testid={testid}] tr").evaluate_all(
        "rows => rows.slice(1).map(r => Array.from(r.cells).map(c => c.innerText))"
    )
    return rows


@pytest.fixture
def tournament(tmp_path: Path) -> Path:
    path = write_schedule(
        tmp_path,
        COMPRESSED + "fixtures:\n  round_robin: {teams: [alpha, bravo, charlie], "
        "first_stream: '+1.5s', interval_s: 0.5, stream_length_s: 0.3}\n",
    )
    state = tmp_path / "state.sqlite"
    assert run_schedule(path, state, services=FAKE, exit_when_done=True, poll_s=0.1) == 0
    return state


def test_queue_submissions_replay_standings_and_pool_pages(
    start: Callable[..., Served], token: Callable[..., str], pool: FakePool, page: Any,
    tournament: Path, tmp_path: Path,
) -> None:
    served = start(expected_match_s=600.0, schedule_state=str(tournament))
    secrets = {name: token(name) for name in ("A1", "B2", "C3")}
    clients = [setup_team(served, secrets[name], name) for name in secrets]
    ids = [c.post("/v1/submissions", json={}).json()["id"] for c in clients]
    wait_for_status(clients[0], ids[0], lambda b: b["state"] == "running")

    _use_token(page, served.url, token(operator=True), "/watch/queue")
    rows = _rows(page, "queue")
    assert [(r[0], r[1], r[2], r[4]) for r in rows] == [
        ("-", ids[0], "A1", "running"),
        ("1", ids[1], "B2", "queued"),
        ("2", ids[2], "C3", "queued"),
    ]
    assert "all 1 match slot(s) busy" in rows[1][6] and rows[1][5].endswith("UTC")
    assert "1 submission(s) ahead" in rows[2][6]
    screenshot(page, "service-queue")

    page.goto(f"{served.url}/watch/standings")
    table = _rows(page, "standings")
    assert page.locator("[data-testid=standings-title]").inner_text() == "test cup: standings"
    ledger = Ledger(tournament)
    schedule = load_schedule(str(ledger.get_meta("schedule")))
    expected = standings(ledger.rows(), [t.name for t in schedule.teams], seed=schedule.name)
    assert sum(s.played for s in expected) == 6
    assert [(r[1], r[2], r[9]) for r in table] == [
        (s.team, str(s.played), str(s.points)) for s in expected
    ]
    assert len(_rows(page, "schedule")) == 3
    screenshot(page, "service-standings")

    page.goto(f"{served.url}/watch/nodes")
    assert page.locator("[data-testid=pool-summary]").inner_text() == "1 match slot(s), 1 in use"
    assert _rows(page, "pool")[0][1] == ids[0]
    (node,) = _rows(page, "nodes")
    assert (node[0], node[1], node[6]) == ("fake-node", "up", "1/1")
    assert node[7].startswith(f"{ids[0]} (A1 v stub)")
    screenshot(page, "service-pool")

    handle = handle_of(served, ids[0])
    pool.finish(handle, {"status": "success"})
    wait_for_status(clients[0], ids[0], lambda b: b["state"] == "done")
    page.wait_for_function(  # the pool page refreshes by itself: the match left the node
        "document.querySelector('[data-testid=nodes] tr:nth-child(2) td:nth-child(8)')"
        ".innerText.startsWith(" + repr(ids[1]) + ")", timeout=20_000)
    public = pool.results_dir(handle) / "public"
    recorded = record_match(tmp_path / "recorded")
    shutil.copy(recorded, public / "replay.hlvsrec")
    shutil.copy(recorded.with_name("api_stats.jsonl"), public / "api_stats.jsonl")

    _use_token(page, served.url, secrets["A1"], "/watch/submissions")
    mine = _rows(page, "submissions")
    assert [(r[0], r[2], r[7]) for r in mine] == [(ids[0], "done", "A1 1 : 0 stub")]
    screenshot(page, "service-submissions")
    page.locator("[data-testid=submissions] a", has_text="replay").click()
    page.wait_for_function("window.hlvsViewer && window.hlvsViewer.ready", timeout=30_000)
    assert page.evaluate("window.hlvsViewer.meta.match_id") == "viewer-test"
    screenshot(page, "service-replay")

    for who, status in ((None, 401), ("B2", 404)):
        headers = {"Authorization": f"Bearer {secrets[who]}"} if who else {}
        answer = httpx.get(f"{served.url}/api/viewer/replays/{ids[0]}/meta", headers=headers)
        assert answer.status_code == status, answer.text
    for c in clients:
        c.close()
