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
    """Sign in once (the token is kept for the browser session), then open ``path``."""
    page.goto(f"{base}/watch/")
    page.evaluate("sessionStorage.clear()")
    page.reload()
    page.locator("[data-testid=token]").fill(secret)
    page.locator("[data-testid=sign-in]").click()
    page.wait_for_selector("[data-testid=who]")
    page.goto(f"{base}{path}")
    page.wait_for_selector("[data-testid=who]")


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
        "first_stream: '+4s', interval_s: 0.5, stream_length_s: 0.3}\n",
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
        "document.querySelector('[data-testid=nodes] tr:nth-child(2) td:nth-child(8)')?"
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


def _text(page: Any) -> str:
    page.wait_for_selector("#app > *")
    page.wait_for_timeout(200)  # the page's last requests
    text: str = page.locator("body").inner_text()
    assert '{"' not in text and '"error"' not in text, text  # never raw JSON
    return text


def test_each_page_with_a_team_token_and_with_an_operator_token(
    start: Callable[..., Served], token: Callable[..., str], pool: FakePool, page: Any,
    tmp_path: Path,
) -> None:
    """One sign-in per browser session; a team sees its matches, the queue with the other
    team's entry anonymised, the ladder and a team's history, and a sentence on the operators'
    pages; an operator sees every page. No page shows raw JSON."""
    served = start()
    alpha_secret = token("Alpha", accepts_friendlies=True)
    beta_secret = token("Beta", accepts_friendlies=True)
    alpha, beta = setup_team(served, alpha_secret, "Alpha"), setup_team(served, beta_secret, "Beta")
    friendly = alpha.post("/v1/submissions", json={"opponent": "Beta"}).json()["id"]
    wait_for_status(alpha, friendly, lambda b: b["state"] == "running")
    handle = handle_of(served, friendly)
    pool.finish(handle, {"status": "success"})  # Alpha 1 : 0 Beta
    wait_for_status(alpha, friendly, lambda b: b["state"] == "done")
    recorded = record_match(tmp_path / "recorded")
    shutil.copy(recorded, pool.results_dir(handle) / "public" / "replay.hlvsrec")
    waiting = beta.post("/v1/submissions", json={}).json()["id"]

    page.goto(f"{served.url}/watch/queue")  # not signed in: the sign-in form, not an error
    page.wait_for_selector("[data-testid=sign-in-form]")
    page.locator("[data-testid=token]").fill("hlvs_000000000000_" + "x" * 43)
    page.locator("[data-testid=sign-in]").click()
    page.wait_for_function("(document.querySelector('[data-testid=error]')?.innerText ?? '')"
                           " !== ''")
    assert "not signed in, or your token is no longer valid" in _text(page)

    _use_token(page, served.url, alpha_secret, "/watch/")
    assert page.locator("[data-testid=who]").inner_text().startswith("team Alpha")
    nav = page.locator("nav a").all_inner_texts()
    assert nav == ["live and replays", "our matches", "queue", "ladder"]
    page.wait_for_selector("[data-testid=replay-list] li")
    assert page.locator("[data-testid=replay-list] li").all_inner_texts() == [
        "Alpha v Beta: viewer-test (3 s, format 3)"]
    assert page.locator("[data-testid=live-list-empty]").inner_text() == \
        "No match is being played now."
    screenshot(page, "role-team-index")
    page.goto(f"{served.url}/watch/submissions")
    (mine,) = _rows(page, "submissions")  # a won match says so, with its score
    assert (mine[0], mine[7], mine[8]) == (friendly, "Alpha 1 : 0 Beta", "won 1-0")
    screenshot(page, "role-team-matches")
    page.goto(f"{served.url}/watch/replay/{friendly}")  # the scoreboard names the teams
    page.wait_for_function("window.hlvsViewer && window.hlvsViewer.ready", timeout=30_000)
    assert page.locator("[data-testid=team-red]").inner_text() == "Alpha"
    assert page.locator("[data-testid=team-blue]").inner_text() == "Beta"
    screenshot(page, "role-team-replay-names")
    page.goto(f"{served.url}/watch/live/{friendly}")  # over: a link to its replay, no empty scene
    page.wait_for_selector("[data-testid=replay-link]")
    assert page.locator("[data-testid=live-status]").inner_text().startswith(
        "This match has ended (Alpha v Beta).")
    assert page.locator("canvas").count() == 0
    assert page.locator("[data-testid=scoreboard]").count() == 0
    screenshot(page, "role-team-live-ended")
    page.locator("[data-testid=replay-link]").click()
    page.wait_for_function("window.hlvsViewer && window.hlvsViewer.ready", timeout=30_000)
    for missing, sentence in (
            ("replay", 'There is no replay "sub_000000000000" that you may watch.'),
            ("live", "This match is not being played now, and it has no replay yet")):
        page.goto(f"{served.url}/watch/{missing}/sub_000000000000")
        page.wait_for_selector("[data-testid=back-link]")
        text = _text(page)
        assert sentence in text and "404" not in text and "/meta" not in text, text
        screenshot(page, f"role-team-no-such-{missing}")
    page.goto(f"{served.url}/watch/queue")
    (entry,) = _rows(page, "queue")
    assert (entry[1], entry[2], entry[3]) == ("-", "another team", "-")
    screenshot(page, "role-team-queue")
    page.goto(f"{served.url}/watch/ladder")  # the ladder, signed in already
    assert [(r[0], r[1], r[5], r[6]) for r in _rows(page, "ladder")] == [
        ("1", "Alpha", "1", "1"), ("2", "Beta", "1", "0")]
    assert page.locator("nav a").all_inner_texts() == nav  # the same bar as every page
    assert page.locator("[data-testid=sign-out]").count() == 1
    assert page.locator("nav input").count() == 0  # no second token box
    screenshot(page, "role-team-ladder")
    page.locator("[data-testid=ladder] a", has_text="Alpha").click()
    (played,) = _rows(page, "ladder-matches")
    assert (played[2], played[3], played[4]) == ("Beta", "1:0", "won")
    screenshot(page, "role-team-history")
    page.locator("[data-testid=ladder-matches] a", has_text="replay").click()
    page.wait_for_function("window.hlvsViewer && window.hlvsViewer.ready", timeout=30_000)
    for path, words in (("/watch/standings", "for the league's operators"),
                        ("/watch/nodes", "for the league's operators")):
        page.goto(f"{served.url}{path}")
        assert words in _text(page), path
    screenshot(page, "role-team-operator-page")

    _use_token(page, served.url, beta_secret, "/watch/submissions")  # the opponent's view
    row = next(r for r in _rows(page, "submissions") if r[0] == friendly)
    assert (row[7], row[8]) == ("Alpha 1 : 0 Beta", "lost 0-1")
    gamma = token("Gamma")  # a team without matches: sentences, not empty tables
    _use_token(page, served.url, gamma, "/watch/submissions")
    assert "No matches yet" in page.locator("[data-testid=submissions-empty]").inner_text()
    page.goto(f"{served.url}/watch/")
    assert "No replay yet" in page.locator("[data-testid=replay-list-empty]").inner_text()
    screenshot(page, "role-team-empty-index")
    page.goto(f"{served.url}/watch/replay/{friendly}")  # another team's match
    text = _text(page)
    assert f'There is no replay "{friendly}" that you may watch.' in text, text
    screenshot(page, "role-team-forbidden-replay")

    _use_token(page, served.url, token(operator=True), "/watch/")
    assert page.locator("nav a").all_inner_texts()[-3:] == ["tournament", "standings", "pool"]
    page.wait_for_selector("[data-testid=replay-list] li")
    assert page.locator("[data-testid=replay-list] li").count() == 1
    screenshot(page, "role-operator-index")
    page.goto(f"{served.url}/watch/submissions")
    every = {r[1]: r for r in _rows(page, "submissions")}
    assert set(every) == {friendly, waiting}
    assert (every[friendly][8], every[friendly][9]) == ("Alpha 1 : 0 Beta", "Alpha won 1-0")
    assert (every[waiting][8], every[waiting][9]) == ("-", "-")
    screenshot(page, "role-operator-matches")
    page.goto(f"{served.url}/watch/queue")
    assert [r[1] for r in _rows(page, "queue")] == [waiting]
    page.goto(f"{served.url}/watch/ladder")
    assert len(_rows(page, "ladder")) == 2
    page.goto(f"{served.url}/watch/standings")
    assert "No tournament runs on this service" in _text(page)
    screenshot(page, "role-operator-tournament")
    page.goto(f"{served.url}/watch/nodes")
    assert _rows(page, "nodes")[0][0] == "fake-node"
    page.goto(f"{served.url}/watch/live/{waiting}")  # queued: not started, nothing to watch
    page.wait_for_function("document.querySelector('[data-testid=live-status]')?.innerText"
                           ".startsWith('This match is not being played now')")
    assert page.locator("canvas").count() == 0
    assert page.locator("[data-testid=scoreboard]").count() == 0
    assert "it may not have started" in _text(page)
    screenshot(page, "role-operator-live-not-started")
    page.goto(f"{served.url}/watch/replay/{friendly}")
    page.wait_for_function("window.hlvsViewer && window.hlvsViewer.ready", timeout=30_000)
    alpha.close()
    beta.close()


def test_docs_render_without_the_internet(start: Callable[..., Served], page: Any) -> None:
    """/docs draws the API from the package's Swagger UI with every request off this host
    refused (a machine without the internet)."""
    served = start()
    outside: list[str] = []

    def only_here(route: Any) -> None:
        if route.request.url.startswith(served.url):
            route.continue_()
        else:
            outside.append(route.request.url)
            route.abort()

    page.route("**/*", only_here)
    page.goto(f"{served.url}/docs")
    page.wait_for_selector(".opblock", timeout=30_000)
    assert page.locator(".opblock").count() > 10
    assert "submission service" in page.locator(".title").first.inner_text()
    assert outside == []
    screenshot(page, "service-docs-offline")


def test_a_new_service_s_pages_say_that_they_are_empty(
        start: Callable[..., Served], token: Callable[..., str], page: Any) -> None:
    """Before any match, every list is a sentence saying why it is empty, never a bare table
    header (operator token: every page)."""
    served = start()
    _use_token(page, served.url, token(operator=True), "/watch/")
    sentences = {
        "/watch/": [("live-list-empty", "No match is being played now."),
                    ("replay-list-empty", "No replay yet")],
        "/watch/submissions": [("submissions-empty", "No team has asked for a test match yet.")],
        "/watch/queue": [("queue-empty", "The queue is empty")],
        "/watch/nodes": [("pool-empty", "No match is playing now.")],
        "/watch/ladder": [("ladder-empty", "No team is on the ladder yet")],
    }
    for path, expected in sentences.items():
        page.goto(f"{served.url}{path}")
        for testid, words in expected:
            page.wait_for_selector(f"[data-testid={testid}]")
            assert words in page.locator(f"[data-testid={testid}]").inner_text(), path
        assert page.locator("main table th").count() == 0 or path == "/watch/nodes", path
        _text(page)  # no raw JSON
        screenshot(page, "empty-" + (path.strip("/").replace("watch/", "").replace("/", "-")
                                     or "index").replace("watch", "index"))
