"""A PostgreSQL server of the test's own (Debian's binaries, its own data folder and port on
127.0.0.1), so that a test may stop, kill and restart it without touching the shared server
other tests use. Runs as the ``postgres`` system user: needs root."""

from __future__ import annotations

import shutil
import subprocess
import tempfile
import time
from pathlib import Path

import psycopg

from tests.integration.service.harness import free_port


def _bin(name: str) -> str:
    found = sorted(Path("/usr/lib/postgresql").glob(f"*/bin/{name}"))
    if not found:
        raise FileNotFoundError(f"no PostgreSQL {name} (apt-get install postgresql)")
    return str(found[-1])


class OwnPostgres:
    """``start()``, ``stop(mode)`` (``fast``: a clean shutdown; ``immediate``: as a crash),
    ``url`` (SQLAlchemy URL of the database ``hlvs``)."""

    def __init__(self) -> None:
        self.folder = Path(tempfile.mkdtemp(prefix="hlvs-own-pg-", dir="/var/tmp"))
        shutil.chown(self.folder, "postgres", "postgres")
        self.data = self.folder / "data"
        self.port = free_port()
        self._as_postgres(_bin("initdb"), "-D", str(self.data), "-A", "trust", "-U", "postgres",
                          "--no-sync")
        self.start()
        with psycopg.connect(self._plain("postgres"), autocommit=True) as connection:
            connection.execute("CREATE DATABASE hlvs")

    @property
    def url(self) -> str:
        return f"postgresql+psycopg://postgres@127.0.0.1:{self.port}/hlvs"

    def _plain(self, database: str) -> str:
        return f"postgresql://postgres@127.0.0.1:{self.port}/{database}"

    def _as_postgres(self, *argv: str) -> None:
        subprocess.run(["runuser", "-u", "postgres", "--", *argv], check=True,
                       capture_output=True, timeout=120)

    def start(self) -> None:
        self._as_postgres(_bin("pg_ctl"), "-D", str(self.data), "-l", str(self.folder / "log"),
                          "-w", "-o", f"-p {self.port} -c listen_addresses=127.0.0.1 "
                          f"-k {self.folder} -c fsync=off", "start")
        deadline = time.monotonic() + 30
        while time.monotonic() < deadline:
            try:
                psycopg.connect(self._plain("postgres"), connect_timeout=2).close()
                return
            except psycopg.OperationalError:
                time.sleep(0.2)
        raise RuntimeError(f"PostgreSQL on port {self.port} did not start")

    def stop(self, mode: str = "fast") -> None:
        self._as_postgres(_bin("pg_ctl"), "-D", str(self.data), "-m", mode, "-w", "stop")

    def close(self) -> None:
        try:
            self.stop("immediate")
        except subprocess.CalledProcessError:
            pass  # already stopped
        shutil.rmtree(self.folder, ignore_errors=True)
