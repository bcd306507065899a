"""Which orchestrator owns which match: one run record per running match id.

``hlvs match`` claims its match id before it creates anything: the record (in
``$HLVS_STATE_DIR/runs/<match id>.json``) names the run (a random id put on every container and
network of the match as :data:`LABEL_RUN`), the orchestrator's process (pid and start time, so a
reused pid is not mistaken for it), the host and the output folder. A second start of a match id
whose orchestrator is alive is refused with these details; ``hlvs cleanup`` touches only matches
whose orchestrator is gone, and finds their output folder here to salvage the teams' logs.
"""

from __future__ import annotations

import contextlib
import json
import os
import socket
import time
import uuid
from collections.abc import Iterator
from dataclasses import asdict, dataclass
from pathlib import Path

from contracts import process
from orchestrator.errors import OrchestratorError
from orchestrator.filelock import held
from orchestrator.match.logfs import safe_name, state_dir

LABEL_RUN = "org.hlvs-runner.run"  # value: the run id of the orchestrator that created it


class MatchRunning(OrchestratorError):
    """A match id is claimed by an orchestrator that is still alive."""

    def __init__(self, record: RunRecord) -> None:
        self.record = record
        started = time.strftime("%Y-%m-%d %H:%M:%S UTC", time.gmtime(record.started_unix_s))
        super().__init__(
            f"match {record.match_id} is already running: orchestrator pid {record.pid} on "
            f"{record.hostname} since {started}, output in {record.out_dir} (run "
            f"{record.run_id}); stop it first, or use another match id"
        )


@dataclass(frozen=True, slots=True, kw_only=True)
class RunRecord:
    match_id: str
    run_id: str
    pid: int
    pid_start: str  # the process start time from /proc (ticks since boot)
    hostname: str
    out_dir: str
    started_unix_s: float
    pid_namespace: str = ""  # the inode of its pid namespace ("": written before it was kept)

    @classmethod
    def from_json(cls, data: object) -> RunRecord | None:
        if not isinstance(data, dict):
            return None
        try:
            return cls(
                match_id=str(data["match_id"]), run_id=str(data["run_id"]), pid=int(data["pid"]),
                pid_start=str(data["pid_start"]), hostname=str(data["hostname"]),
                out_dir=str(data["out_dir"]), started_unix_s=float(data["started_unix_s"]),
                pid_namespace=str(data.get("pid_namespace", "")),
            )
        except (KeyError, TypeError, ValueError):
            return None


def runs_dir() -> Path:
    return state_dir() / "runs"


def record_path(match_id: str) -> Path:
    digest = uuid.uuid5(uuid.NAMESPACE_URL, match_id).hex[:8]  # distinct ids, same safe name
    return runs_dir() / f"{safe_name(match_id)}-{digest}.json"


def owner_alive(record: RunRecord) -> bool:
    """True while the orchestrator that wrote ``record`` runs, or runs where this process cannot
    tell (another host, another pid namespace: an orchestrator in a container or a cluster job
    sharing the state folder, whose pid may be free or someone else's here)."""
    if not record.pid_namespace:  # a record of an earlier version: host, pid and start time
        return record.hostname != socket.gethostname() or \
            process.start_time(record.pid) == record.pid_start
    return not process.ended(hostname=record.hostname, namespace=record.pid_namespace,
                             pid=record.pid, start=record.pid_start)  # fmt: skip


def read(match_id: str) -> RunRecord | None:
    try:
        return RunRecord.from_json(json.loads(record_path(match_id).read_text()))
    except (OSError, ValueError):
        return None


def records() -> list[RunRecord]:
    found = []
    for path in sorted(runs_dir().glob("*.json")) if runs_dir().is_dir() else []:
        try:
            record = RunRecord.from_json(json.loads(path.read_text()))
        except (OSError, ValueError):
            continue
        if record is not None:
            found.append(record)
    return found


def forget(record: RunRecord) -> None:
    """Remove the record if it is still ``record``'s (a newer run keeps its own)."""
    with _locked():
        current = read(record.match_id)
        if current is not None and current.run_id == record.run_id:
            record_path(record.match_id).unlink(missing_ok=True)


@contextlib.contextmanager
def _locked() -> Iterator[None]:
    runs_dir().mkdir(parents=True, exist_ok=True, mode=0o700)
    with held(runs_dir() / ".lock"):
        yield


@dataclass(frozen=True, slots=True, kw_only=True)
class Claim:
    record: RunRecord
    previous: RunRecord | None  # the run before ours, whose orchestrator is gone


@contextlib.contextmanager
def claim(match_id: str, out_dir: Path) -> Iterator[Claim]:
    """Own ``match_id`` for the duration; raises :class:`MatchRunning` if a live orchestrator
    owns it. The previous owner's record (dead) is handed back for salvage."""
    pid = os.getpid()
    record = RunRecord(
        match_id=match_id, run_id=uuid.uuid4().hex, pid=pid,
        pid_start=process.start_time(pid) or "",
        hostname=socket.gethostname(), out_dir=str(out_dir.resolve()),
        started_unix_s=time.time(), pid_namespace=process.pid_namespace(),
    )
    with _locked():
        previous = read(match_id)
        if previous is not None and owner_alive(previous):
            raise MatchRunning(previous)
        path = record_path(match_id)
        tmp = path.with_suffix(".tmp")
        tmp.write_text(json.dumps(asdict(record), indent=2) + "\n")
        os.chmod(tmp, 0o600)
        os.replace(tmp, path)
    try:
        yield Claim(record=record, previous=previous)
    finally:
        forget(record)


__all__ = [
    "Claim", "LABEL_RUN", "MatchRunning", "RunRecord", "claim", "forget", "owner_alive", "read",
    "record_path", "records", "runs_dir",
]
