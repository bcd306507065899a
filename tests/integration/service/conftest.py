"""The service under test: the real app served by uvicorn on 127.0.0.1, over SQLite or
PostgreSQL, called over HTTP with httpx."""

from __future__ import annotations

import os
import socket
import threading
import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import httpx
import pytest
import uvicorn

from service import Settings, create_app
from service.app import PoolFactory
from service.db import Scope, make_engine, migrate, session_factory, transaction
from service.tokens import issue


def free_port() -> int:
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        port: int = sock.getsockname()[1]
        return port


@dataclass
class Served:
    url: str
    settings: Settings
    server: uvicorn.Server
    thread: threading.Thread

    def client(self, token: str | None = None) -> httpx.Client:
        headers = {"Authorization": f"Bearer {token}"} if token else {}
        return httpx.Client(base_url=self.url, headers=headers, timeout=30)

    def stop(self) -> None:
        self.server.should_exit = True
        self.thread.join(timeout=30)


def serve(settings: Settings, *, pool_factory: PoolFactory | None = None,
          start_worker: bool = False) -> Served:
    """Start the app on a free loopback port; returns once it answers."""
    port = free_port()
    app = create_app(settings, pool_factory=pool_factory, start_worker=start_worker)
    config = uvicorn.Config(app, host="127.0.0.1", port=port, log_level="warning",
                            lifespan="on")
    server = uvicorn.Server(config)
    thread = threading.Thread(target=server.run, name=f"service-{port}", daemon=True)
    thread.start()
    url = f"http://127.0.0.1:{port}"
    deadline = time.monotonic() + 30
    while time.monotonic() < deadline:
        if server.started:
            return Served(url=url, settings=settings, server=server, thread=thread)
        if not thread.is_alive():
            break
        time.sleep(0.02)
    raise RuntimeError(f"the service did not start on {url}")


def _postgres_url() -> str | None:
    from tests.integration.service.postgres import test_database_url

    return test_database_url()


@pytest.fixture(params=["sqlite", "postgresql"])
def db_url(request: pytest.FixtureRequest, tmp_path: Path) -> str:
    if request.param == "sqlite":
        return f"sqlite:///{tmp_path / 'service.sqlite'}"
    url = _postgres_url()
    if url is None:
        if os.geteuid() == 0 and Path("/etc/debian_version").is_file():
            pytest.fail("no test PostgreSQL: run scripts/ensure-postgres.sh (make test does)")
        pytest.skip("PostgreSQL is set up only on Debian as root (scripts/ensure-postgres.sh)")
    from tests.integration.service.postgres import fresh_database

    return fresh_database(url)


@pytest.fixture
def settings(tmp_path: Path, db_url: str) -> Settings:
    return Settings(data_dir=tmp_path / "data", database_url=db_url, max_upload_bytes=20_000)


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
