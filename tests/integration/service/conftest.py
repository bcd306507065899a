"""The service under test: the real app served by uvicorn on 127.0.0.1, over SQLite or
PostgreSQL, called over HTTP with httpx."""

from __future__ import annotations

import os
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import pytest

from service import Settings
from service.db import Scope, make_engine, migrate, session_factory, transaction
from service.tokens import issue
from tests.integration.service.harness import Served, serve


def _postgres_url() -> str | None:
    from tests.integration.service.postgres import test_database_url

    return test_database_url()


@pytest.fixture(params=["sqlite", "postgresql"])
def db_url(request: pytest.FixtureRequest, tmp_path: Path) -> Iterator[str]:
    if request.param == "sqlite":
        yield f"sqlite:///{tmp_path / 'service.sqlite'}"
        return
    url = _postgres_url()
    if url is None:
        if os.geteuid() == 0 and Path("/etc/debian_version").is_file():
            pytest.fail("no test PostgreSQL: run scripts/ensure-postgres.sh (make test does)")
        pytest.skip("PostgreSQL is set up only on Debian as root (scripts/ensure-postgres.sh)")
    from tests.integration.service.postgres import drop_database, fresh_database

    database = fresh_database(url)
    yield database
    drop_database(database)


@pytest.fixture
def settings(tmp_path: Path, db_url: str) -> Settings:
    return Settings(data_dir=tmp_path / "data", database_url=db_url, max_upload_bytes=20_000,
                    token_cache_s=0.0)


@pytest.fixture
def served(settings: Settings) -> Iterator[Served]:
    instance = serve(settings)
    yield instance
    instance.stop()


TokenMaker = Callable[..., str]


@pytest.fixture
def make_token(settings: Settings) -> Iterator[TokenMaker]:
    """``make_token(team="A")`` adds team A when missing and returns a fresh team token;
    ``make_token(operator=True)`` an operator token; ``days=`` sets the expiry."""
    engine = make_engine(settings.db_url)
    migrate(engine)
    factory = session_factory(engine)

    def make(*, team: str | None = None, operator: bool = False, days: float | None = 1,
             **team_fields: Any) -> str:
        from sqlalchemy import select

        from service.admin import add_team
        from service.db import Team

        with transaction(factory) as session:
            if team is not None and session.scalar(
                    select(Team).where(Team.name == team)) is None:
                add_team(session, name=team, **team_fields)
            issued = issue(session, scope=Scope.OPERATOR if operator else Scope.TEAM,
                           team=None if operator else team, days=days)
        return issued.secret

    yield make
    engine.dispose()
