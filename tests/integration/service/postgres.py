"""The test PostgreSQL server started by scripts/ensure-postgres.sh (Debian's, on 127.0.0.1).

Each test gets a database of its own, created from the ``hlvs_test`` role's connection.
"""

from __future__ import annotations

import os
import uuid

URL_FILE = "/var/lib/hlvs/postgres-test-url"


def test_database_url() -> str | None:
    """The server's URL (from the environment or the file the set-up script writes)."""
    url = os.environ.get("HLVS_TEST_POSTGRES_URL")
    if url:
        return url
    try:
        with open(URL_FILE, encoding="utf-8") as handle:
            return handle.read().strip() or None
    except OSError:
        return None


def fresh_database(url: str) -> str:
    """A new empty database on the server of ``url``; returns its URL."""
    import psycopg

    name = "hlvs_t_" + uuid.uuid4().hex[:10]
    base, _, _ = url.rpartition("/")
    plain = url.replace("postgresql+psycopg://", "postgresql://")
    with psycopg.connect(plain, autocommit=True) as connection:
        connection.execute(f'CREATE DATABASE "{name}"')
    return f"{base}/{name}"


def drop_database(url: str) -> None:
    """Remove a database made by :func:`fresh_database` (connections to it are ended)."""
    import psycopg

    base, _, name = url.rpartition("/")
    admin = (base + "/postgres").replace("postgresql+psycopg://", "postgresql://")
    with psycopg.connect(admin, autocommit=True) as connection:
        connection.execute(f'DROP DATABASE IF EXISTS "{name}" WITH (FORCE)')
