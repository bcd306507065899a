"""The results of finished matches live in the service's database (SQLite and PostgreSQL): the
queue worker records them as a match ends, and ``GET /v1/matches``, a submission's status, the
ladder and the notifications read them from there, with the match folders removed. A database
made before the results tables gets them by its migration, filled from the folders still there
when the worker starts."""

from __future__ import annotations

import shutil
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import httpx
import pytest
from sqlalchemy import select

from cluster.fake import FakePool
from service import Settings
from service.db import Submission, make_engine, migrate, session_factory, transaction
from service.db.ladder import RatedMatch
from service.db.results import MatchResultRow, MatchTeamRow
from tests.integration.service.harness import Served, serve
from tests.unit.service.conftest import FakePreflight, wait_for_status
from tests.unit.service.test_submissions import handle_of, setup_team

Maker = Callable[..., str]


@pytest.fixture
def worker_settings(tmp_path: Path, db_url: str) -> Settings:
    return Settings(data_dir=tmp_path / "data", database_url=db_url, max_upload_bytes=20_000,
                    worker_poll_s=0.05, stub_image="hlvs-runner/stub:test", video=False,
                    token_cache_s=0.0)


def _serve(settings: Settings, pool: FakePool) -> Served:
    return serve(settings, start_worker=True, pool_factory=lambda _s: pool,
                 preflight=FakePreflight())


def _played(served: Served, http: httpx.Client, pool: FakePool, body: dict[str, Any]) -> str:
    """Submit, let the fake pool play it 1:0 for red, wait for the end; the submission id."""
    sid: str = http.post("/v1/submissions", json=body).json()["id"]
    wait_for_status(http, sid, lambda b: b["state"] == "running")
    pool.finish(handle_of(served, sid), {"status": "success"})
    wait_for_status(http, sid, lambda b: b["state"] == "done")
    return sid


def test_matches_answer_scores_from_the_database_with_the_match_folders_removed(
        worker_settings: Settings, make_token: Maker) -> None:
    pool = FakePool(slots=1)
    served = _serve(worker_settings, pool)
    try:
        secrets = {name: make_token(team=name, accepts_friendlies=True)
                   for name in ("Alpha", "Beta")}
        alpha = setup_team(served, secrets["Alpha"], "Alpha")
        setup_team(served, secrets["Beta"], "Beta").close()
        test_match = _played(served, alpha, pool, {})
        friendly = _played(served, alpha, pool, {"opponent": "Beta"})
        for sid in (test_match, friendly):
            folder = Path(handle_of(served, sid))
            assert (pool.results_dir(str(folder)) / "results.json").is_file()
            shutil.rmtree(folder)  # every file of the match gone
        engine = make_engine(worker_settings.db_url)
        with transaction(session_factory(engine)) as session:  # the ladder rates it again
            session.query(RatedMatch).delete()
        engine.dispose()
        matches = {m["id"]: m for m in alpha.get("/v1/matches").json()}
        result = matches[test_match]["result"]
        assert result["score"] == {"red": 1, "blue": 0} and result["winner"] == "red"
        assert result["shootout"] is None and result["final_state"] == "FINISHED"
        assert result["halves_playing"] == [1, 2] and result["playing_s"] == 80.0
        red, blue = result["teams"]["red"], result["teams"]["blue"]
        assert (red["team"], red["goals"], red["kicks"], red["shots"], red["robots"]) == (
            "Alpha", 1, 1, 1, 1)
        assert (blue["team"], blue["goals"], blue["kicks"], blue["robots_exited"]) == (
            "stub", 0, 0, 0)
        assert matches[friendly]["result"]["teams"]["blue"]["team"] == "Beta"
        assert alpha.get(f"/v1/submissions/{test_match}").json()["result"] == result
        with served.client(secrets["Beta"]) as beta:  # the opponent of the friendly sees it
            seen = {m["id"]: m for m in beta.get("/v1/matches").json()}
            assert set(seen) == {friendly}
            assert seen[friendly]["result"]["score"] == {"red": 1, "blue": 0}
            deadline = time.monotonic() + 10
            while beta.get("/v1/ladder").json()["matches_rated"] != 1:
                assert time.monotonic() < deadline, "the ladder did not rate the friendly"
                time.sleep(0.1)
            ladder = {t["team"]: t for t in beta.get("/v1/ladder").json()["teams"]}
        assert (ladder["Alpha"]["won"], ladder["Beta"]["lost"]) == (1, 1)
        schema = alpha.get("/openapi.json").json()["components"]["schemas"]
        assert {"MatchResultView", "SideResult"} <= set(schema)
        alpha.close()
    finally:
        served.stop()


def test_a_database_from_before_the_results_tables_gets_them_filled_from_the_folders(
        worker_settings: Settings, make_token: Maker) -> None:
    """As an upgrade finds it: matches ended under the schema of 0006, their rows deleted as a
    database of that version would lack them; the next start records them from their
    folders, a match whose folder is gone stays without a result."""
    pool = FakePool(slots=1)
    served = _serve(worker_settings, pool)
    try:
        alpha = setup_team(served, make_token(team="Alpha"), "Alpha")
        kept, removed = _played(served, alpha, pool, {}), _played(served, alpha, pool, {})
    finally:
        served.stop()
    shutil.rmtree(Path(handle_of(served, removed)))
    engine = make_engine(worker_settings.db_url)
    with transaction(session_factory(engine)) as session:
        for table in (MatchTeamRow, MatchResultRow):
            session.query(table).delete()
    from alembic import command
    from alembic.config import Config

    from service.db.session import MIGRATIONS

    config = Config()
    config.set_main_option("script_location", str(MIGRATIONS))
    with engine.begin() as connection:
        config.attributes["connection"] = connection
        command.downgrade(config, "0006_ladder")
    migrate(engine)  # what the next start does
    with transaction(session_factory(engine)) as session:
        assert session.scalars(select(MatchResultRow)).all() == []
        assert {s.state for s in session.scalars(select(Submission))} == {"done"}
    engine.dispose()
    served = _serve(worker_settings, pool)
    try:
        http = served.client(make_token(team="Alpha"))
        wait_for_status(http, kept, lambda b: b["result"] is not None)
        matches = {m["id"]: m for m in http.get("/v1/matches").json()}
        assert matches[kept]["result"]["score"] == {"red": 1, "blue": 0}
        assert matches[removed]["result"] is None
        http.close()
    finally:
        served.stop()
