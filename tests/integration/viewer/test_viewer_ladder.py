"""The ladder's pages inside a real ``hlvs serve`` (fake match pool writing real results files,
SQLite) in Chromium: the table in rating order with a team token, a team's history and matches,
the replay of a friendly opened by its opponent, and errors as sentences."""

from __future__ import annotations

import shutil
from collections.abc import Callable
from pathlib import Path
from typing import Any

import httpx
import pytest

from cluster.fake import FakePool
from tests.integration.service.harness import Served
from tests.integration.viewer.conftest import screenshot
from tests.unit.service.test_ladder import finish, running_match, wait_rated
from tests.unit.service.test_submissions import setup_team
from tests.unit.viewer.replays import record_match

pytestmark = pytest.mark.browser


def _rows(page: Any, testid: str) -> list[list[str]]:
    page.wait_for_selector(f"[data-testid={testid}] tr")
    rows: list[list[str]] = page.locator(f"[data-testid={testid}] tr").evaluate_all(
        "rows => rows.slice(1).map(r => Array.from(r.cells).map(c => c.innerText))")
    return rows


def _sign_in(page: Any, secret: str) -> None:
    page.wait_for_selector("[data-testid=sign-in-form]")
    page.locator("[data-testid=token]").fill(secret)
    page.locator("[data-testid=sign-in]").click()
    page.wait_for_selector("[data-testid=who]")


def test_ladder_page_table_team_history_and_replay(
    start: Callable[..., Served], token: Callable[..., str], pool: FakePool, page: Any,
    tmp_path: Path,
) -> None:
    served = start(ladder_every_s=0.01)
    secrets = {name: token(name, accepts_friendlies=True) for name in ("Ant", "Bee", "Cat")}
    for name, secret in secrets.items():
        setup_team(served, secret, name).close()
    recorded = record_match(tmp_path / "recorded", seconds=1.0)
    first: tuple[str, str, str] | None = None
    for n in range(3):
        sid, handle, team, opponent = running_match(served)
        if first is None:
            first = (sid, team, opponent)
            public = pool.results_dir(handle) / "public"
            public.mkdir(parents=True, exist_ok=True)
            shutil.copy(recorded, public / "replay.hlvsrec")
        finish(pool, handle, 1, 0)  # the team the ladder picked (red) wins
        wait_rated(served, n + 1)
    assert first is not None
    with served.client(secrets["Ant"]) as http:
        expected = http.get("/v1/ladder").json()["teams"]

    page.goto(f"{served.url}/watch/ladder")
    page.wait_for_selector("[data-testid=sign-in-form]")  # no token yet: the sign-in, no JSON
    assert "{" not in page.locator("main").inner_text()
    _sign_in(page, secrets["Ant"])
    assert page.locator("nav a").all_inner_texts() == [
        "live and replays", "our matches", "queue", "ladder"]  # the bar of every page
    assert page.locator("[data-testid=who]").inner_text().startswith("team Ant")
    rows = _rows(page, "ladder")
    assert [r[1] for r in rows] == [t["team"] for t in expected]
    ratings = [float(r[2]) for r in rows]
    assert ratings == sorted(ratings, reverse=True) and ratings[0] > ratings[-1]
    assert sum(int(r[5]) for r in rows) == 6
    assert "3 match(es) rated" in page.locator("[data-testid=ladder-summary]").inner_text()
    screenshot(page, "service-ladder")

    sid, team, opponent = first
    page.goto(f"{served.url}/watch/ladder/{opponent}")  # the opponent of the first friendly
    page.locator("[data-testid=sign-out]").click()
    _sign_in(page, secrets[opponent])
    matches = _rows(page, "ladder-matches")
    assert page.locator("[data-testid=ladder-history] polyline").count() == 1
    oldest = matches[-1]
    assert (oldest[1], oldest[2], oldest[3], oldest[4]) == ("friendly", team, "0:1", "lost")
    screenshot(page, "service-ladder-team")
    page.locator("[data-testid=ladder-matches] tr:last-child a", has_text="replay").click()
    page.wait_for_function("window.hlvsViewer && window.hlvsViewer.ready", timeout=30_000)
    assert page.url.endswith(f"/watch/replay/{sid}")

    page.goto(f"{served.url}/watch/ladder/Nobody")
    page.wait_for_selector("[data-testid=error]")
    assert page.locator("[data-testid=error]").inner_text() == \
        "There is no such team on the ladder."
    outsider = token("Dog")  # a team that plays no friendlies still reads the ladder
    answer = httpx.get(f"{served.url}/v1/ladder",
                       headers={"Authorization": f"Bearer {outsider}"})
    assert answer.status_code == 200 and len(answer.json()["teams"]) == 3
    operator = httpx.get(f"{served.url}/v1/ladder/{team}",
                         headers={"Authorization": f"Bearer {token(operator=True)}"})
    assert operator.status_code == 200 and operator.json()["matches"]
