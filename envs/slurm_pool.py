"""Remote simulators allocated from a Slurm cluster: ``remotes="slurm:N"``.

Each remote is one Slurm batch job (submitted through :class:`cluster.slurm.SlurmPool`)
whose step is ``python -m envs.slurm_node``: it starts the simulator image with ``remote`` on
the node it got, writes where it answers to ``remote.json`` in the job's folder, and keeps it
while this process renews its lease. :class:`SlurmLauncher` submits the jobs, waits until every
remote answers a health check (a job that Slurm keeps waiting or that fails is reported with
Slurm's reason, its state and the last lines of its log), and releases them at close:
``scancel`` (the job stops its container with a grace period; the cluster's epilog removes any
container labelled with the job id) and waits until Slurm no longer lists them. A process that
dies without closing stops renewing the lease; each job then releases its remote by itself
after ``lease`` seconds.

The job folders (address, lease, failure, ``slurm-<job>.out``) must be on a file system that
this machine and the nodes share (the same machine for the one-machine test cluster; NFS or
similar for a cluster of VMs): ``dir=`` names it (default: a new folder under the system's
temporary folder, removed at a clean close).
"""

from __future__ import annotations

import atexit
import json
import logging
import os
import shlex
import shutil
import sys
import tempfile
import threading
import time
import uuid
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path

from envs.errors import EnvConfigError, RemoteStartFailed
from envs.remote import RemoteAddress, probe
from envs.slurm_node import ADDRESS_FILE, FAILED_FILE, LEASE_FILE
from envs.wire import WireError

log = logging.getLogger(__name__)

START_TIMEOUT_S = 300.0
RELEASE_TIMEOUT_S = 60.0
LEASE_S = 60.0
GRACE_S = 10.0
POLL_S = 0.3


@dataclass(frozen=True, slots=True, kw_only=True)
class SlurmOptions:
    """What ``remotes="slurm:N?key=value&..."`` may set."""

    conf: str | None = None  # slurm.conf of the cluster (default: $SLURM_CONF)
    partition: str | None = None
    account: str | None = None
    dir: str | None = None  # shared folder for the job folders
    lease_s: float = LEASE_S
    start_timeout_s: float = START_TIMEOUT_S
    cpus: int | None = None  # CPUs per remote (default: a whole node)

    @classmethod
    def from_query(cls, query: dict[str, str | float | int]) -> SlurmOptions:
        """From the options of ``slurm:N?...`` (:func:`envs.remote.parse_slurm`)."""

        def text(key: str) -> str | None:
            value = query.get(key)
            return None if value is None else str(value)

        return cls(
            conf=text("conf"), partition=text("partition"), account=text("account"),
            dir=text("dir"), lease_s=float(query.get("lease", LEASE_S)),
            start_timeout_s=float(query.get("timeout", START_TIMEOUT_S)),
            cpus=int(query["cpus"]) if "cpus" in query else None,
        )  # fmt: skip


class _Job:
    def __init__(self, job_id: str, folder: Path) -> None:
        self.job_id = job_id
        self.folder = folder
        self.address: RemoteAddress | None = None
        self.node = ""

    def describe(self) -> str:
        where = f" on {self.node}" if self.node else ""
        return f"Slurm job {self.job_id}{where}"


class SlurmLauncher:
    """The :class:`envs.remote_pool.Launcher` of remotes that Slurm jobs run."""

    def __init__(
        self, options: SlurmOptions | None = None, *, image: str | None = None,
        python: str = sys.executable, host_network: bool | None = None,
    ) -> None:  # fmt: skip
        from cluster import HOST_NETNS, SlurmPool
        from envs.docker_pool import default_image

        self.options = options or SlurmOptions()
        conf = self.options.conf or os.environ.get("SLURM_CONF") or None
        if conf is not None and not Path(conf).is_file():  # Slurm would retry for a minute
            raise EnvConfigError(
                field="remotes conf" if self.options.conf else "SLURM_CONF", value=conf,
                expected="the slurm.conf of a cluster (a file)",
            )  # fmt: skip
        # Nodes of the one-machine cluster share this host's Docker engine: the job enters the
        # host's network namespace and reports the container's bridge address.
        self.host_network = Path(HOST_NETNS).exists() if host_network is None else host_network
        self.slurm = SlurmPool(slurm_conf=conf, partition=self.options.partition,
                               python=python, host_network=self.host_network)  # fmt: skip
        self.image = image or default_image()
        self.pool_id = uuid.uuid4().hex[:10]
        self._own_root = self.options.dir is None
        base = Path(self.options.dir) if self.options.dir else Path(tempfile.gettempdir())
        base.mkdir(parents=True, exist_ok=True)
        self.root = Path(tempfile.mkdtemp(prefix=f"hlvs-env-slurm-{self.pool_id}-", dir=base))
        self.jobs: list[_Job] = []
        self._submitted = 0
        self._closed = False
        self._lease_stop = threading.Event()
        self._lease_thread = threading.Thread(
            target=self._renew, daemon=True, name=f"hlvs-env-lease-{self.pool_id}"
        )
        self._lease_thread.start()
        atexit.register(self.close)

    # --- the Launcher protocol ---------------------------------------------------------------

    def start(self, count: int) -> list[RemoteAddress]:
        with _slurm_errors():
            jobs = [self._submit(i) for i in range(count)]
            self._wait(jobs)
        return [job.address for job in jobs if job.address is not None]

    def replace(self, index: int) -> RemoteAddress:
        with _slurm_errors():
            old = self.jobs[index]
            self.slurm.cancel_jobs([old.job_id])
            job = self._submit(index)
            self._wait([job])
        assert job.address is not None
        return job.address

    def diagnose(self, index: int) -> str | None:
        """Why remote ``index`` stopped answering: the cause its job recorded (container exit
        code, last log lines), or Slurm's state of the job and the end of its log."""
        job = self.jobs[index]
        deadline = time.monotonic() + 5.0  # the job notices a dead container within a second
        while True:
            failed = _read_json(job.folder / FAILED_FILE)
            if failed is not None:
                return f"{job.describe()}: {failed.get('cause')}"
            entry = self.slurm.entries([job.job_id]).get(job.job_id)
            if entry is None:
                return f"{job.describe()} ended ({self._final(job)}){self._log_tail(job)}"
            if time.monotonic() > deadline:
                return None
            time.sleep(POLL_S)

    def close(self) -> None:
        """Cancel every job (the remotes get their grace period) and wait until Slurm no longer
        lists them; then remove the job folders when they are ours."""
        if self._closed:
            return
        self._closed = True
        atexit.unregister(self.close)
        ids = [job.job_id for job in self.jobs]
        try:
            self.slurm.cancel_jobs(ids)
            left = self._wait_gone(ids, RELEASE_TIMEOUT_S)
        finally:
            self._lease_stop.set()
        if left:
            log.warning(
                "Slurm jobs %s still listed %g s after scancel (the cluster's KillWait ends them)",
                ",".join(left),
                RELEASE_TIMEOUT_S,
            )
        else:
            log.info("released %d remote(s) of Slurm pool %s", len(ids), self.pool_id)
            if self._own_root:
                shutil.rmtree(self.root, ignore_errors=True)

    # --- jobs --------------------------------------------------------------------------------

    def _submit(self, index: int) -> _Job:
        folder = self.root / f"remote-{index}-{self._submitted}"
        from cluster import ENV_REMOTE_COMMENT

        self._submitted += 1
        folder.mkdir()
        (folder / LEASE_FILE).write_text("0")
        job_id = self.slurm.submit_script(
            self._script(folder), name=f"hlvs-env-{self.pool_id}-{index}", work=folder,
            account=self.options.account, cpus=self.options.cpus, comment=ENV_REMOTE_COMMENT,
        )  # fmt: skip
        job = _Job(job_id, folder)
        if index < len(self.jobs):
            self.jobs[index] = job
        else:
            self.jobs.append(job)
        log.info("remote %d: Slurm job %s submitted (%s)", index, job_id, folder)
        return job

    def _script(self, folder: Path) -> str:
        from cluster import HOST_NETNS

        prefix = ["nsenter", f"--net={HOST_NETNS}"] if self.host_network else []
        command = [*prefix, self.slurm.python, "-m", "envs.slurm_node", "--image", self.image,
                   "--job-dir", str(folder),
                   "--advertise", "bridge" if self.host_network else "node",
                   "--lease-s", f"{self.options.lease_s:g}", "--grace-s", f"{GRACE_S:g}",
                   "--health-timeout-s", f"{self.options.start_timeout_s:g}"]  # fmt: skip
        return "#!/bin/sh\nexec " + " ".join(shlex.quote(c) for c in command) + "\n"

    def _wait(self, jobs: list[_Job]) -> None:
        """Until every job's remote answers; RemoteStartFailed (naming the job) otherwise."""
        deadline = time.monotonic() + self.options.start_timeout_s
        waiting = list(jobs)
        reasons: dict[str, str] = {}
        while waiting:
            entries = self.slurm.entries([job.job_id for job in waiting])
            for job in list(waiting):
                entry = entries.get(job.job_id)
                if entry is not None:
                    job.node = entry.nodes if entry.state == "RUNNING" else job.node
                    why = "" if entry.reason in ("None", "") else f": {entry.reason}"
                    reasons[job.job_id] = entry.state.lower() + why
                failed = _read_json(job.folder / FAILED_FILE)
                if failed is not None:
                    raise RemoteStartFailed(address=job.describe(), reason=str(failed.get("cause")))
                found = _read_json(job.folder / ADDRESS_FILE)
                if found is not None:
                    address = RemoteAddress(str(found["host"]), int(str(found["port"])))
                    job.node = str(found.get("node") or job.node)
                    try:
                        probe(address)
                    except (OSError, WireError) as exc:
                        reasons[job.job_id] = f"reported {address}, which does not answer: {exc}"
                    else:
                        job.address = address
                        waiting.remove(job)
                        log.info("remote %s answers at %s", job.describe(), address)
                        continue
                if entry is None and job.address is None:
                    raise RemoteStartFailed(
                        address=job.describe(),
                        reason=f"the job ended ({self._final(job)}) before its remote answered"
                        f"{self._log_tail(job)}",
                    )  # fmt: skip
            if waiting and time.monotonic() > deadline:
                job = waiting[0]
                raise RemoteStartFailed(
                    address=job.describe(),
                    reason=f"no remote after {self.options.start_timeout_s:g} s "
                    f"({reasons.get(job.job_id, 'not yet in the queue')})",
                )  # fmt: skip
            if waiting:
                time.sleep(POLL_S)

    def _wait_gone(self, ids: list[str], timeout_s: float) -> list[str]:
        deadline = time.monotonic() + timeout_s
        left = list(self.slurm.entries(ids))
        while left and time.monotonic() < deadline:
            time.sleep(POLL_S)
            left = list(self.slurm.entries(left))
        return left

    def _final(self, job: _Job) -> str:
        state = self.slurm.accounting_state(job.job_id)
        return state.replace("|", ", exit ") if state else "state unknown"

    @staticmethod
    def _log_tail(job: _Job) -> str:
        logs = sorted(job.folder.glob("slurm-*.out"))
        if not logs:
            return ""
        lines = logs[-1].read_text(errors="replace").strip().splitlines()[-5:]
        return "; last log lines: " + " | ".join(lines) if lines else ""

    def _renew(self) -> None:
        """Touch every lease file a few times per lease period."""
        period = max(1.0, self.options.lease_s / 4)
        while not self._lease_stop.wait(period):
            for job in list(self.jobs):
                try:
                    (job.folder / LEASE_FILE).write_text(str(time.time()))
                except OSError as exc:
                    log.warning("cannot renew the lease of %s: %s", job.describe(), exc)


@contextmanager
def _slurm_errors() -> Iterator[None]:
    """Slurm's commands failing (no cluster, a refused submission) as RemoteStartFailed."""
    from cluster import PoolError

    try:
        yield
    except PoolError as exc:
        raise RemoteStartFailed(address=f"Slurm ({exc.handle})", reason=exc.reason) from exc


def _read_json(path: Path) -> dict[str, object] | None:
    try:
        data = json.loads(path.read_text())
    except (OSError, ValueError):
        return None
    return data if isinstance(data, dict) else None
