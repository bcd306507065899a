"""Service tests with a fake match pool and a fake pre-flight check (the boundaries), over the
real app served on 127.0.0.1 with SQLite."""

from __future__ import annotations

import json
import time
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import httpx
import pytest

from cluster.fake import FakePool
from orchestrator.config import TeamConfig
from service import Settings
from service.db import Scope, make_engine, migrate, session_factory, transaction
from service.errors import InvalidInput, PreflightFailed
from service.tokens import issue
from tests.integration.service.harness import Served, serve


def wait_for_status(http: httpx.Client, submission: str,
                    predicate: Callable[[dict[str, Any]], bool],
                    timeout_s: float = 10.0) -> dict[str, Any]:
    """Poll a submission's status until ``predicate`` holds; the status then."""
    deadline = time.monotonic() + timeout_s
    while True:
        body: dict[str, Any] = http.get(f"/v1/submissions/{submission}").json()
        if predicate(body):
            return body
        assert time.monotonic() < deadline, f"timed out; last status {body}"
        time.sleep(0.1)


EXAMPLE_TEAM = Path(__file__).parents[3] / "configs" / "examples" / "scrimmage_1v1" / \
    "team_red.json"


def team_doc(name: str = "Alpha", image: str = "hlvs-runner/stub") -> dict[str, Any]:
    doc: dict[str, Any] = json.loads(EXAMPLE_TEAM.read_text())
    doc["name"] = name
    doc["image"] = image
    return doc


class FakePreflight:
    """Passes, unless the image's name contains 'bad' (fails at pull) or 'unfit' (a problem of
    the file that only the check finds)."""

    def __init__(self) -> None:
        self.calls = 0

    def __call__(self, team: TeamConfig, settings: Settings) -> float:
        self.calls += 1
        if "bad" in str(team.image):
            raise PreflightFailed(stage="pull", image=str(team.image), cause="manifest unknown")
        if "unfit" in str(team.image):
            raise InvalidInput("team_config.json has 1 problem(s): /image: unfit for the match")
        return 0.01


@pytest.fixture
def settings(tmp_path: Path) -> Settings:
    return Settings(data_dir=tmp_path / "data", max_upload_bytes=20_000, worker_poll_s=0.05,
                    stub_image="hlvs-runner/stub:test", webhook_backoff_s=0.1, video=False)


@pytest.fixture
def pool() -> FakePool:
    return FakePool(slots=1)


@pytest.fixture
def start(settings: Settings, pool: FakePool) -> Iterator[Callable[..., Served]]:
    """``start()`` serves the app with the worker, the fake pool and the fake pre-flight;
    call it again after ``.stop()`` to restart on the same database."""
    running: list[Served] = []

    def begin(**changes: Any) -> Served:
        current = settings.with_(**changes) if changes else settings
        served = serve(current, start_worker=True, pool_factory=lambda _s: pool,
                       preflight=FakePreflight())
        running.append(served)
        return served

    yield begin
    for served in running:
        served.stop()


@pytest.fixture
def token(settings: Settings) -> Iterator[Callable[..., str]]:
    engine = make_engine(settings.db_url)
    migrate(engine)
    factory = session_factory(engine)

    def make(team: str | None = None, *, operator: bool = False, **team_fields: Any) -> str:
        from sqlalchemy import select

        from service.admin import add_team
        from service.db import Team

        with transaction(factory) as session:
            if team is not None and session.scalar(
                    select(Team).where(Team.name == team)) is None:
                add_team(session, name=team, **team_fields)
            return issue(session, scope=Scope.OPERATOR if operator else Scope.TEAM,
                         team=None if operator else team, days=1).secret

    yield make
    engine.dispose()
