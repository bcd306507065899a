"""Delivery benchmark: one log set of N files / M MB to a local SFTP or S3 server.

``python -m benchmarks.delivery --target sftp|s3 [--server NAME] --files 200 --mb 50
--json`` starts the server on 127.0.0.1 (sftp: sshd when root, else asyncssh; s3: SeaweedFS when
installed, else moto), enqueues a match whose team folder holds the files, delivers it and
prints one JSON line: seconds to enqueue (hashing included) and to deliver, MB/s, files/s.
"""

from __future__ import annotations

import argparse
import json
import logging
import os
import sys
import tempfile
import time
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:  # the delivery code and the test servers are imported after the arguments
    from orchestrator.config.documents import S3Document, SftpDocument
    from testkit.s3 import MotoServer, SeaweedServer

__all__ = ["main"]

SERVERS = {"sftp": ("sshd", "asyncssh"), "s3": ("seaweedfs", "moto")}


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="hlvs bench delivery")
    parser.add_argument("--target", choices=sorted(SERVERS), required=True,
                        help="delivery target kind")
    parser.add_argument("--server", choices=[s for pair in SERVERS.values() for s in pair],
                        help="server on loopback (default: sshd as root, else asyncssh; "
                        "seaweedfs when installed, else moto)")
    parser.add_argument("--files", type=int, default=200, help="files in the log set (default 200)")
    parser.add_argument("--mb", type=float, default=50.0,
                        help="total megabytes in the log set (default 50)")
    parser.add_argument("--json", action="store_true", help="print one JSON line only")
    args = parser.parse_args(argv)
    if not args.json:
        logging.basicConfig(level=logging.INFO, format="%(levelname)s %(name)s: %(message)s")
    server = args.server or _default_server(args.target)
    if server not in SERVERS[args.target]:
        parser.error(f"--server {server} does not serve --target {args.target}")
    with tempfile.TemporaryDirectory(prefix="hlvs-delivery-bench-") as tmp:
        result = run(Path(tmp), server=server, files=args.files, total_mb=args.mb)
    result["target"] = args.target
    print(json.dumps(result) if args.json else json.dumps(result, indent=2))
    return 0 if result["delivered"] else 1


def run(workdir: Path, *, server: str, files: int, total_mb: float) -> dict[str, Any]:
    """Start ``server``, deliver one set of ``files`` files / ``total_mb`` MB, stop it."""
    from orchestrator.delivery.deliver import RetryPolicy, deliver_pending
    from orchestrator.delivery.enqueue import enqueue_match_logs

    started = time.monotonic()
    body, stop = _start(server, workdir)
    startup_s = time.monotonic() - started
    try:
        kind = "sftp" if server in SERVERS["sftp"] else "s3"
        creds = workdir / "credentials.json"
        creds.write_text(json.dumps({"type": kind, "credentials": body}), encoding="utf-8")
        creds.chmod(0o600)
        total_bytes = _write_match(workdir / "match", files, int(total_mb * 1e6))
        store = workdir / "store"
        t0 = time.monotonic()
        enqueue_match_logs(
            workdir / "match",
            match_id="bench",
            teams={"red": ("Bench", creds)},
            public_target=None,
            store=store,
        )
        t1 = time.monotonic()
        [outcome] = deliver_pending(store, retry=RetryPolicy(attempts=2, initial_delay_s=0.5))
        t2 = time.monotonic()
    finally:
        stop()
    deliver_s = t2 - t1
    return {
        "bench": "delivery",
        "server": server,
        "files": files,
        "bytes": total_bytes,
        "server_start_s": round(startup_s, 2),
        "enqueue_s": round(t1 - t0, 3),
        "deliver_s": round(deliver_s, 3),
        "mb_per_s": round(total_bytes / 1e6 / deliver_s, 1),
        "files_per_s": round(files / deliver_s, 1),
        "delivered": outcome.delivered,
        "uploaded_files": outcome.uploaded_files,
        "error": outcome.error.kind if outcome.error else None,
    }


def _default_server(target: str) -> str:
    from testkit.s3 import weed_binary

    if target == "sftp":
        return "sshd" if os.geteuid() == 0 else "asyncssh"
    return "seaweedfs" if weed_binary() is not None else "moto"


def _start(
    server: str, workdir: Path
) -> tuple[SftpDocument | S3Document, Callable[[], None]]:
    """The server running, the ``credentials`` of a credentials.json for it, its stop."""
    from testkit.s3 import MotoServer, SeaweedServer
    from testkit.sftp import AsyncsshServer, SshdServer

    if server in ("sshd", "asyncssh"):
        sftp = SshdServer.start() if server == "sshd" else AsyncsshServer.start(workdir)
        body: SftpDocument = {
            "hostname": "127.0.0.1",
            "port": sftp.port,
            "username": sftp.username,
            "password": sftp.password,
            "host_key": sftp.host_key,
            "path": sftp.upload_path,
        }
        return body, sftp.stop
    from orchestrator.config.credentials import S3Credentials
    from orchestrator.delivery.s3 import create_bucket

    s3: MotoServer | SeaweedServer = (
        SeaweedServer.start(workdir) if server == "seaweedfs" else MotoServer.start()
    )
    who = s3.writer if isinstance(s3, SeaweedServer) else s3.admin
    admin = S3Credentials(
        source=workdir,
        access_id=s3.admin.access_id,
        access_secret=s3.admin.access_secret,
        bucket="bench",
        endpoint_url=s3.endpoint_url,
    )
    create_bucket(admin)
    s3_body: S3Document = {
        "access_id": who.access_id,
        "access_secret": who.access_secret,
        "bucket": "bench",
        "endpoint_url": s3.endpoint_url,
    }
    return s3_body, s3.stop


def _write_match(match: Path, files: int, total_bytes: int) -> int:
    size = max(1, total_bytes // files)
    written = 0
    for i in range(files):
        robot = f"red-{i % 4 + 1}"
        path = match / "teams" / "red" / robot / "robocup-logs" / f"log-{i:04d}.bin"
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_bytes(os.urandom(size))
        written += size
    return written


if __name__ == "__main__":
    sys.exit(main())
