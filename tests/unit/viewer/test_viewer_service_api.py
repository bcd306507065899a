"""The viewer's parts of ``hlvs serve`` over HTTP (the served app, fake pool, SQLite): the score
of each match for the matches pages, the teams' names in a replay's meta, and ``/docs`` served
from the package's own Swagger UI (no CDN)."""

from __future__ import annotations

import re
import shutil
from collections.abc import Callable
from pathlib import Path

from cluster.fake import FakePool
from tests.integration.service.harness import Served
from tests.unit.service.conftest import wait_for_status
from tests.unit.service.test_submissions import handle_of, setup_team
from tests.unit.viewer.replays import record_match


def test_results_and_replay_meta_name_the_teams_for_whoever_may_watch(
        start: Callable[..., Served], token: Callable[..., str], pool: FakePool,
        tmp_path: Path) -> None:
    served = start()
    secrets = {name: token(name, accepts_friendlies=True) for name in ("Alpha", "Beta", "Gamma")}
    alpha = setup_team(served, secrets["Alpha"], "Alpha")
    setup_team(served, secrets["Beta"], "Beta").close()  # the opponent's team file
    friendly = alpha.post("/v1/submissions", json={"opponent": "Beta"}).json()["id"]
    wait_for_status(alpha, friendly, lambda b: b["state"] == "running")
    handle = handle_of(served, friendly)
    pool.finish(handle, {"status": "success"})  # red (Alpha) 1 : 0 blue (Beta)
    wait_for_status(alpha, friendly, lambda b: b["state"] == "done")
    shutil.copy(record_match(tmp_path / "recorded", seconds=1.0),
                pool.results_dir(handle) / "public" / "replay.hlvsrec")
    expected = {"red": "Alpha", "blue": "Beta", "score": {"red": 1, "blue": 0},
                "shootout": None, "winner": "red"}
    for who in ("Alpha", "Beta", None):
        with served.client(secrets[who] if who else token(operator=True)) as http:
            assert http.get("/api/viewer/results").json() == {friendly: expected}, who
            meta = http.get(f"/api/viewer/replays/{friendly}/meta").json()
            assert meta["teams"] == {"red": "Alpha", "blue": "Beta"}, who
    with served.client(secrets["Gamma"]) as http:
        assert http.get("/api/viewer/results").json() == {}
        assert http.get(f"/api/viewer/replays/{friendly}/meta").status_code == 404
    with served.client() as http:
        assert http.get("/api/viewer/results").status_code == 401
    shutil.rmtree(handle)  # the scores are the database's: the match folder is not needed
    assert alpha.get("/api/viewer/results").json() == {friendly: expected}
    alpha.close()


def test_docs_are_served_from_the_package_without_the_internet(
        start: Callable[..., Served]) -> None:
    served = start()
    with served.client() as http:
        page = http.get("/docs")
        assert page.status_code == 200
        html = page.text
        assert not re.search(r"""(src|href)\s*=\s*["']?https?://""", html), html
        assert "cdn." not in html and "/openapi.json" in html
        assets = re.findall(r"""(?:src|href)\s*=\s*["']([^"']+)["']""", html)
        assert "/watch/static/swagger/swagger-ui-bundle.js" in assets, assets
        for asset in assets:
            answer = http.get(asset)
            assert answer.status_code == 200 and len(answer.content) > 500, asset
        assert http.get("/redoc").status_code == 404  # FastAPI's ReDoc page loads from a CDN
        assert http.get("/openapi.json").json()["paths"]
