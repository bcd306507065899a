"""The service's SQLite database opened by a second engine of the same process while the first
has connections open, then by another process: the first engine's connections keep working.

Making the file private used to open and close it, and closing any descriptor of a file drops
every POSIX lock the process holds on it: the other process, closing its last connection,
then took the database for unused and deleted its WAL under the first engine ("disk I/O
error", met when ``hlvs serve`` started again after ``hlvs admin`` had run)."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

from sqlalchemy import text

from service.db import make_engine, migrate


def test_another_engine_then_another_process_leave_open_connections_working(
    tmp_path: Path,
) -> None:
    path = tmp_path / "data" / "service.sqlite"
    url = f"sqlite:///{path}"
    first = make_engine(url)
    migrate(first)
    with first.begin() as connection:
        connection.execute(text("CREATE TABLE marks (n INTEGER)"))
        connection.execute(text("INSERT INTO marks VALUES (1)"))
    held = first.connect()  # an open connection of this process, as a running service has
    assert held.execute(text("SELECT count(*) FROM marks")).scalar() == 1
    held.rollback()  # open, idle: no transaction holding the write lock
    second = make_engine(url)  # the same file made private again by a second engine
    second.dispose()
    other = subprocess.run(
        [sys.executable, "-c",
         "import sqlite3, sys; c = sqlite3.connect(sys.argv[1]);"
         " c.execute('INSERT INTO marks VALUES (2)'); c.commit(); c.close()", str(path)],
        capture_output=True, text=True, timeout=60, check=False,
    )  # fmt: skip
    assert other.returncode == 0, other.stderr
    # the first engine writes on (a token issued, a result stored), a new one reads it
    held.execute(text("INSERT INTO marks VALUES (3)"))
    held.commit()
    held.close()
    fresh = make_engine(url)
    with fresh.connect() as connection:
        assert connection.execute(text("SELECT count(*) FROM marks")).scalar() == 3
        assert connection.execute(text("PRAGMA integrity_check")).scalar() == "ok"
    fresh.dispose()
    first.dispose()
    assert path.stat().st_mode & 0o777 == 0o600
