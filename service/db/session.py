"""Database engine, sessions and migrations (the one module that creates SQLAlchemy engines)."""

from __future__ import annotations

import logging
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

from alembic import command
from alembic.config import Config
from sqlalchemy import Engine, create_engine, event
from sqlalchemy.exc import DBAPIError, InterfaceError, OperationalError
from sqlalchemy.orm import Session, sessionmaker

log = logging.getLogger(__name__)

MIGRATIONS = Path(__file__).parent / "migrations"


def make_engine(url: str) -> Engine:
    """An engine for ``url``; SQLite gets WAL, a busy timeout, foreign keys and real transactions
    (each one whole, nested blocks included)."""
    if url.startswith("sqlite"):
        if url.startswith("sqlite:///"):
            _private_sqlite(Path(url.removeprefix("sqlite:///")))
        engine = create_engine(url, connect_args={"check_same_thread": False, "timeout": 30},
                               pool_size=20, max_overflow=40)

        @event.listens_for(engine, "connect")
        def _pragmas(dbapi_connection: Any, _record: Any) -> None:
            # the driver's own transaction handling off: it would start a transaction only at the
            # first write, and a SAVEPOINT released outside one commits at once (a row inserted
            # in a nested block became visible before the rest of its transaction)
            dbapi_connection.isolation_level = None
            cursor = dbapi_connection.cursor()
            cursor.execute("PRAGMA journal_mode=WAL")
            cursor.execute("PRAGMA busy_timeout=30000")
            cursor.execute("PRAGMA foreign_keys=ON")
            cursor.close()

        @event.listens_for(engine, "begin")
        def _begin(connection: Any) -> None:
            # IMMEDIATE: the write lock up front (waiting up to the busy timeout), so a
            # transaction that reads then writes never fails on a snapshot another one changed
            connection.exec_driver_sql("BEGIN IMMEDIATE")

        return engine
    return create_engine(url, pool_size=20, max_overflow=30, pool_pre_ping=True,
                         connect_args={"connect_timeout": CONNECT_TIMEOUT_S})


CONNECT_TIMEOUT_S = 5
"""How long a new PostgreSQL connection may take (an unreachable server answers 503 then)."""
UNAVAILABLE_RETRY_S = 5
"""The ``Retry-After`` of a request answered while the database cannot be reached."""
_BUSY = ("locked", "busy", "deadlock", "serializ", "lock timeout", "could not obtain lock")
_UNAVAILABLE = ("connection failed", "connection refused", "could not connect",
                "server closed the connection", "shutting down", "starting up",
                "terminating connection", "timeout expired", "connection is closed",
                "connection timed out", "consuming input failed", "the connection is lost",
                "no connection to the server", "in recovery mode")


def database_busy(exc: DBAPIError) -> bool:
    """A database too busy to answer in time (SQLite's lock past its busy timeout, a
    PostgreSQL lock or serialization failure): the request may be retried at once."""
    text = str(exc.orig).lower()
    return isinstance(exc, OperationalError) and any(word in text for word in _BUSY)


def database_unavailable(exc: DBAPIError) -> bool:
    """A database that cannot be reached now (a PostgreSQL server stopped, restarting or
    unreachable): the request may be retried in a moment."""
    text = str(exc.orig).lower()
    return exc.connection_invalidated or (
        isinstance(exc, OperationalError | InterfaceError)
        and any(phrase in text for phrase in _UNAVAILABLE))


def _private_sqlite(path: Path) -> None:
    """The database file (and its WAL files, which SQLite creates with the file's mode) 0600;
    a missing folder is created 0700. An existing file is not opened: closing any descriptor of
    it drops every POSIX lock this process holds on it, those of its open SQLite connections
    too, and another process closing its last connection would then take the database for
    unused and delete its WAL under them ("disk I/O error")."""
    from orchestrator import make_private_file, private_dir

    if path.name in ("", ":memory:"):
        return
    private_dir(path.parent, only_if_new=True)
    if path.exists():
        path.chmod(0o600)
    else:  # no connection of this process can hold a lock on a file not made yet
        make_private_file(path)
    for extra in ("-wal", "-shm", "-journal"):
        companion = path.with_name(path.name + extra)
        if companion.exists():
            companion.chmod(0o600)


def migrate(engine: Engine) -> None:
    """Bring the schema to the newest migration (idempotent)."""
    logging.getLogger("alembic").setLevel(logging.WARNING)
    config = Config()
    config.set_main_option("script_location", str(MIGRATIONS))
    with engine.begin() as connection:
        config.attributes["connection"] = connection
        command.upgrade(config, "head")
    log.debug("database schema at the newest migration (%s)", engine.url)


def session_factory(engine: Engine) -> sessionmaker[Session]:
    return sessionmaker(engine, expire_on_commit=False)


@contextmanager
def transaction(factory: sessionmaker[Session]) -> Iterator[Session]:
    """A session that commits on success and rolls back on any error."""
    with factory() as session, session.begin():
        yield session


__all__ = ["make_engine", "migrate", "session_factory", "transaction"]
