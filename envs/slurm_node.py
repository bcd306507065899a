"""``python -m envs.slurm_node``: one remote simulator on a Slurm node, the batch step of a job
that :class:`envs.slurm_pool.SlurmLauncher` submitted.

It starts the simulator image with ``remote --port 7700`` on the node's Docker engine (labelled
``org.hlvs-runner.slurm-job=<job id>``, so the cluster's epilog removes it even after a
``SIGKILL``), waits until it answers a health check, and writes where it answers to
``<job dir>/remote.json`` (``{"host", "port", "node", "job_id", "container"}``). Then it keeps
the remote until one of:

- ``SIGTERM`` / ``SIGINT`` (``scancel``): the container gets SIGTERM, ``--grace-s`` seconds,
  and is removed; exit 0;
- the client stops renewing its lease (``<job dir>/lease`` unchanged for ``--lease-s``
  seconds of this node's clock: the client process died): as above, exit 0;
- the container stops: its cause (exit code, last log lines) goes to ``<job dir>/failed.json``
  and the job ends with exit 1.

Where the remote answers (``--advertise``): ``bridge``, the container's address on the engine's
bridge (a cluster whose nodes share the submitting machine's engine, like the one-machine test
cluster), or ``node``, the node's own address (the one it reaches the submitting host with)
and the port published on it (a cluster of real machines).
"""

from __future__ import annotations

import argparse
import json
import logging
import os
import signal
import socket
import sys
import threading
import time
from pathlib import Path
from types import FrameType

ADDRESS_FILE = "remote.json"
FAILED_FILE = "failed.json"
LEASE_FILE = "lease"

log = logging.getLogger("envs.slurm_node")


def write_json(path: Path, data: dict[str, object]) -> None:
    tmp = path.with_name(path.name + ".tmp")
    tmp.write_text(json.dumps(data))
    tmp.replace(path)


def node_address() -> str:
    """This node's address towards the submitting host (the source address a UDP socket
    would use to reach it; no packet is sent)."""
    target = os.environ.get("SLURM_SUBMIT_HOST") or socket.gethostname()
    try:
        with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as probe:
            probe.connect((socket.gethostbyname(target), 9))
            return str(probe.getsockname()[0])
    except OSError:
        return socket.gethostbyname(socket.gethostname())


class Lease:
    """The client's lease: the lease file must change at least every ``lease_s`` seconds."""

    def __init__(self, path: Path, lease_s: float) -> None:
        self.path = path
        self.lease_s = lease_s
        self._seen = self._stamp()
        self._since = time.monotonic()

    def _stamp(self) -> tuple[int, int] | None:
        try:
            st = self.path.stat()
        except OSError:
            return None
        return (st.st_mtime_ns, st.st_size)

    def expired(self) -> bool:
        stamp = self._stamp()
        if stamp != self._seen:
            self._seen, self._since = stamp, time.monotonic()
            return False
        return time.monotonic() - self._since > self.lease_s


def serve(args: argparse.Namespace, stop: threading.Event) -> int:
    from envs.docker_pool import DockerLauncher
    from envs.errors import RemoteStartFailed
    from orchestrator.engine import LABEL_SLURM_JOB  # the cluster's epilog removes by it

    job_dir: Path = args.job_dir
    job_id = os.environ.get("SLURM_JOB_ID", "")
    node = os.environ.get("SLURMD_NODENAME") or socket.gethostname()
    labels = {LABEL_SLURM_JOB: job_id} if job_id else {}
    launcher = DockerLauncher(
        image=args.image, labels=labels, health_timeout_s=args.health_timeout_s,
        publish_host="0.0.0.0" if args.advertise == "node" else "127.0.0.1", unix=False,
    )  # fmt: skip
    try:
        try:
            address = launcher.start(1)[0]
        except RemoteStartFailed as exc:
            write_json(job_dir / FAILED_FILE, {"cause": f"did not start: {exc.reason}"})
            return 1
        host, port = address.host, address.port
        if args.advertise == "node":
            host, port = node_address(), launcher.published_port(0) or port
        write_json(job_dir / ADDRESS_FILE, {
            "host": host, "port": port, "node": node, "job_id": job_id,
            "container": launcher.containers[0][:12],
        })  # fmt: skip
        log.info("remote of job %s on %s answers at %s:%d", job_id, node, host, port)
        lease = Lease(job_dir / LEASE_FILE, args.lease_s)
        while not stop.wait(1.0):
            cause = launcher.diagnose(0)
            if cause is not None:
                write_json(job_dir / FAILED_FILE, {"cause": cause})
                log.error("the remote stopped: %s", cause)
                return 1
            if lease.expired():
                log.warning("lease not renewed for %g s: the client is gone", args.lease_s)
                break
        launcher.stop(args.grace_s)
        return 0
    finally:
        launcher.close()


def main(argv: list[str]) -> int:
    parser = argparse.ArgumentParser(
        prog="python -m envs.slurm_node",
        description="run one remote simulator in a Slurm job until scancel or lease expiry",
    )
    parser.add_argument("--image", required=True, help="simulator image reference")
    parser.add_argument(
        "--job-dir",
        type=Path,
        required=True,
        help="folder shared with the client (address, lease, failure)",
    )
    parser.add_argument(
        "--advertise",
        choices=("bridge", "node"),
        default="node",
        help="which address to report: engine bridge or the node's own",
    )
    parser.add_argument(
        "--lease-s",
        type=float,
        default=60.0,
        help="stop when the client has not renewed its lease for this long",
    )
    parser.add_argument(
        "--grace-s",
        type=float,
        default=10.0,
        help="seconds between SIGTERM and SIGKILL of the container",
    )
    parser.add_argument(
        "--health-timeout-s",
        type=float,
        default=120.0,
        help="how long the container may take to answer",
    )
    args = parser.parse_args(argv)
    logging.basicConfig(
        level=logging.INFO,
        stream=sys.stderr,
        format="%(asctime)s %(levelname)s %(name)s: %(message)s",
    )
    stop = threading.Event()

    def on_signal(signum: int, _frame: FrameType | None) -> None:
        log.info("%s: releasing the remote", signal.Signals(signum).name)
        stop.set()

    signal.signal(signal.SIGTERM, on_signal)
    signal.signal(signal.SIGINT, on_signal)
    return serve(args, stop)


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
