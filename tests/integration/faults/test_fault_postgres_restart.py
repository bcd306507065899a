"""Fault: PostgreSQL stops under the running service (a clean restart, then a crash) while a
match runs and requests come in.

Outcome: while the database is away every request is answered 503 with ``Retry-After`` (never a
500, never a hang), the queue worker keeps retrying, and once the server is back the service
answers again without a restart of its own: the match that ended meanwhile is recorded, the
submissions and files written before are all there, new ones are taken. Nothing is lost but the
requests refused during the outage (their clients were told to retry).

The server is the test's own (:mod:`tests.integration.faults.own_postgres`), never the shared
one; the match pool is the in-memory one (the fault is the database's)."""

from __future__ import annotations

import os
from collections.abc import Iterator
from pathlib import Path

import httpx
import pytest

from cluster.fake import FakePool
from service import Settings
from service.db import Scope, make_engine, migrate, session_factory, transaction
from service.tokens import issue
from tests.integration.faults.own_postgres import OwnPostgres
from tests.integration.service.harness import serve
from tests.unit.service.conftest import FakePreflight, team_doc, wait_for_status

pytestmark = [pytest.mark.root, pytest.mark.slow,
              pytest.mark.skipif(os.geteuid() != 0, reason="runs PostgreSQL as its user")]


@pytest.fixture
def postgres() -> Iterator[OwnPostgres]:
    try:
        server = OwnPostgres()
    except FileNotFoundError as exc:
        pytest.skip(str(exc))
    yield server
    server.close()


def _token(url: str, team: str) -> str:
    from service.admin import add_team

    engine = make_engine(url)
    migrate(engine)
    with transaction(session_factory(engine)) as session:
        add_team(session, name=team)
        secret = issue(session, scope=Scope.TEAM, team=team, days=1).secret
    engine.dispose()
    return secret


def _outage_answers(http: httpx.Client) -> list[tuple[int, str | None]]:
    """Status and Retry-After of reads and writes while the database is away."""
    answers = []
    for method, path, body in (("GET", "/v1/submissions", None),
                               ("POST", "/v1/submissions", {}),
                               ("GET", "/v1/team/files/team_config", None)):
        response = http.request(method, path, json=body)
        answers.append((response.status_code, response.headers.get("Retry-After")))
        assert "Traceback" not in response.text
    return answers


@pytest.mark.parametrize("mode", ["fast", "immediate"])
def test_postgres_restarted_under_the_service(postgres: OwnPostgres, tmp_path: Path,
                                              mode: str) -> None:
    settings = Settings(data_dir=tmp_path / "data", database_url=postgres.url,
                        max_upload_bytes=20_000, worker_poll_s=0.05, token_cache_s=0.0,
                        stub_image="hlvs-runner/stub:test", video=False)
    token = _token(postgres.url, "Alpha")
    pool = FakePool(slots=1)
    served = serve(settings, start_worker=True, pool_factory=lambda _s: pool,
                   preflight=FakePreflight())
    try:
        with served.client(token) as http:
            assert http.put("/v1/team/files/team_config", json=team_doc()).status_code == 201
            sid = http.post("/v1/submissions", json={}).json()["id"]
            wait_for_status(http, sid, lambda b: b["state"] == "running")

            postgres.stop(mode)
            answers = _outage_answers(http)
            assert answers == [(503, "5")] * 3, answers
            handle = next(iter(pool.handles))
            pool.finish(handle, {"status": "success"})  # the match ends while it is away
            assert _outage_answers(http) == [(503, "5")] * 3

            postgres.start()
            done = wait_for_status(http, sid, lambda b: b["state"] == "done", 30)
            assert done["attempts"] == 1 and pool.started == [f"{sid}-a1"]
            assert len(http.get("/v1/team/files/team_config").json()) == 1
            second = http.post("/v1/submissions", json={})
            assert second.status_code == 201, second.text
            wait_for_status(http, second.json()["id"], lambda b: b["state"] == "running", 30)
            listed = [s["id"] for s in http.get("/v1/submissions").json()]
            assert sorted(listed) == sorted([sid, second.json()["id"]])
    finally:
        served.stop()
