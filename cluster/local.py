"""The local pool: each match is one ``hlvs match`` process on this host's Docker engine.

The process runs in its own session, so it outlives a restart of the service; its pid and
start time are written to ``<work_dir>/pool.json`` before ``submit`` returns, and a later
service process reads them back to tell a running match from a finished or lost one. Cancel
sends SIGTERM, which ``hlvs match`` answers with a graceful stop and a complete report.
The handle is the work folder. :func:`start_match` is how every ``hlvs match`` process is
started, here and by the tournament scheduler.
"""

from __future__ import annotations

import ctypes
import json
import logging
import os
import signal
import socket
import subprocess
import sys
import threading
from collections.abc import Sequence
from pathlib import Path
from typing import IO

from cluster import JobState, JobStatus, MatchJob
from cluster.errors import PoolError
from cluster.nodes import NodeJob, PoolNode
from contracts import files, process
from orchestrator import open_private_append, write_private

log = logging.getLogger(__name__)

STATE_FILE = "pool.json"
LOG_FILE = "orchestrator.log"


def process_start_time(pid: int) -> int | None:
    """The kernel's start time of ``pid`` (clock ticks since boot), None when it is gone."""
    start = process.start_time(pid)
    return None if start is None else int(start)


def _memory_mb() -> tuple[int, int | None]:
    """This host's memory and the part still available (``/proc/meminfo``), in MiB."""
    values: dict[str, int] = {}
    try:
        for line in Path("/proc/meminfo").read_text().splitlines():
            key, _, rest = line.partition(":")
            number = rest.split()[0] if rest.split() else ""
            if number.isdigit():
                values[key] = int(number) // 1024  # kB
    except OSError:
        pass
    return values.get("MemTotal", 0), values.get("MemAvailable")


def start_match(
    game_path: Path,
    out: Path,
    output: IO[bytes],
    *,
    python: str = sys.executable,
    hlvs_args: Sequence[str] = (),
    match_args: Sequence[str] = (),
    own_session: bool = False,
    die_with_parent: bool = False,
) -> subprocess.Popen[bytes]:
    """Start ``hlvs match GAME --out OUT`` in a child process writing to ``output``.
    ``hlvs_args``: options of ``hlvs`` itself, before the command; ``match_args``: more options
    of ``hlvs match``. ``own_session``: the child has a session of its own and outlives this
    process (a pool's match, adopted by a restarted service); ``die_with_parent``: it gets
    SIGTERM, which stops the match and collects what was played, when this process dies
    (Linux; the tournament scheduler). Raises OSError when it cannot be started."""
    command = [python, "-m", "hlvs", *hlvs_args, "match", str(game_path), "--out", str(out),
               *match_args]
    return subprocess.Popen(
        command, stdout=output, stderr=subprocess.STDOUT, stdin=subprocess.DEVNULL,
        start_new_session=own_session,
        preexec_fn=_die_with_parent if die_with_parent and sys.platform == "linux" else None,
    )


def _die_with_parent() -> None:  # pragma: no cover - runs in the child before exec
    """Linux: the child gets SIGTERM when its parent dies."""
    libc = ctypes.CDLL("libc.so.6", use_errno=True)
    libc.prctl(1, signal.SIGTERM)  # PR_SET_PDEATHSIG


class LocalDockerPool:
    def __init__(self, *, slots: int = 1, python: str = sys.executable,
                 extra_args: tuple[str, ...] = ()) -> None:
        self.slots = slots
        self.python = python
        self.extra_args = extra_args
        self._children: dict[str, subprocess.Popen[bytes]] = {}
        self._seen: set[str] = set()  # handles seen running (started here or asked about)
        self._lock = threading.Lock()

    # MatchPool ---------------------------------------------------------------------------
    def submit(self, job: MatchJob) -> str:
        handle = str(job.work_dir.resolve())
        with self._lock:
            if self._alive(handle):
                log.info("match %s already running in the local pool; adopted", job.match_id)
                return handle
            out = self.results_dir(handle)
            out.mkdir(parents=True, exist_ok=True)
            with os.fdopen(open_private_append(job.work_dir / LOG_FILE), "ab") as log_file:
                try:
                    child = start_match(job.game_path.resolve(), out, log_file,
                                        python=self.python, hlvs_args=self.extra_args,
                                        match_args=job.match_args, own_session=True)
                except OSError as exc:
                    raise PoolError(handle=handle, reason=f"cannot start hlvs match: {exc}") \
                        from exc
            started = process_start_time(child.pid)
            state = {"pid": child.pid, "start_time": started, "match_id": job.match_id}
            write_private(job.work_dir / STATE_FILE, json.dumps(state))
            self._children[handle] = child
            self._seen.add(handle)
            log.info("match %s started in the local pool (pid %d)", job.match_id, child.pid)
            return handle

    def status(self, handle: str) -> JobStatus:
        with self._lock:
            if self._alive(handle):
                self._seen.add(handle)
                return JobStatus(state=JobState.RUNNING)
            self._seen.discard(handle)
        if (self.results_dir(handle) / files.REPORT).is_file():
            return JobStatus(state=JobState.FINISHED)
        detail = "the match process ended without a report.json"
        child = self._children.get(handle)
        if child is not None and child.returncode is not None:
            detail += f" (exit code {child.returncode})"
        elif not (Path(handle) / STATE_FILE).is_file():
            detail = "the match was never started"
        return JobStatus(state=JobState.LOST, detail=detail + self._log_tail(handle))

    def cancel(self, handle: str) -> None:
        state = self._state(handle)
        with self._lock:
            pid = None if state is None else state.get("pid")
            if not isinstance(pid, int) or not self._alive(handle):
                return
            try:
                os.kill(pid, signal.SIGTERM)
                log.info("match in %s asked to stop (SIGTERM to pid %s)", handle, pid)
            except ProcessLookupError:
                pass

    def results_dir(self, handle: str) -> Path:
        return Path(handle) / "out"

    def nodes(self) -> list[PoolNode]:
        """This host: its CPUs, load and memory, and the matches running here (the ones
        this process started or was asked about: a restarted service learns of the others
        from its first status queries)."""
        jobs = []
        with self._lock:
            for handle in sorted(self._seen):
                state = self._state(handle)
                if state is None or not self._alive(handle):
                    continue
                match_id = state.get("match_id")
                jobs.append(NodeJob(job_id=str(state.get("pid")), state="running",
                                    match_id=match_id if isinstance(match_id, str) else None))
        total_mb, free_mb = _memory_mb()
        return [PoolNode(
            name=socket.gethostname(), state="up", reason="", features=("docker",),
            cpus=os.cpu_count() or 1, cpus_allocated=None, cpu_load=round(os.getloadavg()[0], 2),
            memory_mb=total_mb, memory_free_mb=free_mb, slots=self.slots, jobs=tuple(jobs),
        )]  # fmt: skip

    # helpers -----------------------------------------------------------------------------
    def _state(self, handle: str) -> dict[str, object] | None:
        try:
            data = json.loads((Path(handle) / STATE_FILE).read_text())
        except (OSError, ValueError):
            return None
        return data if isinstance(data, dict) else None

    def _alive(self, handle: str) -> bool:
        child = self._children.get(handle)
        if child is not None:
            return child.poll() is None  # reaps our own child
        state = self._state(handle)
        if state is None:
            return False
        pid, recorded = state.get("pid"), state.get("start_time")
        if not isinstance(pid, int):
            return False
        current = process_start_time(pid)
        return current is not None and current == recorded  # same pid, same process

    def _log_tail(self, handle: str) -> str:
        try:
            lines = (Path(handle) / LOG_FILE).read_text(errors="replace").strip().splitlines()
        except OSError:
            return ""
        return (": " + lines[-1][-300:]) if lines else ""


__all__ = ["LocalDockerPool", "process_start_time"]
