"""The machines of a match pool, as an operator sees them: :class:`PoolNode` per node with its
state, why it is out of service, its features, CPUs and memory, and the jobs (matches) on it.

The local pool has one node, this host; the Slurm pool has the cluster's nodes as ``sinfo``
lists them. The text formats of Slurm's commands are parsed here (pure functions); running
the commands stays in :mod:`cluster.slurm`.
"""

from __future__ import annotations

import itertools
import re
from dataclasses import dataclass, field

from contracts import JSONObject, to_data

# sinfo -N: one line per node and partition; the reason last (free text that may hold '|')
SINFO_FORMAT = "%N|%T|%C|%m|%e|%O|%f|%E"
# squeue: every job with its nodes (empty while pending)
SQUEUE_NODES_FORMAT = "%i|%j|%T|%N|%k"
MATCH_JOB_PREFIX = "hlvs-"  # the Slurm pool names a match's job hlvs-<match id>
# the Slurm comment of a job that serves a learning environment (not a match); its name is
# hlvs-env-..., which a match id could also give, so the comment tells them apart
ENV_REMOTE_COMMENT = "hlvs:environment-remote"


@dataclass(frozen=True, slots=True, kw_only=True)
class NodeJob:
    """A job on a node: a Slurm job (``job_id`` its id) or a local match process (its pid)."""

    job_id: str
    match_id: str | None  # the match it plays; None for a job that is not a match
    state: str  # RUNNING, COMPLETING... (Slurm's) or "running"

    def to_json(self) -> JSONObject:
        data: JSONObject = to_data(self)
        return data


@dataclass(frozen=True, slots=True, kw_only=True)
class PoolNode:
    """One machine of the pool."""

    name: str
    state: str  # Slurm's node state (idle, allocated, mixed, drained, down...) or "up"
    reason: str  # why the node is drained or down, "" when nothing is wrong
    features: tuple[str, ...]
    cpus: int
    cpus_allocated: int | None  # None where the pool does not allocate CPUs (local)
    cpu_load: float | None  # 1-minute load average, None when unknown
    memory_mb: int
    memory_free_mb: int | None
    slots: int  # matches the node plays at once
    jobs: tuple[NodeJob, ...] = field(default=())

    def to_json(self) -> JSONObject:
        """The node as JSON (``hlvs pool nodes --json``, the operators' API): its fields."""
        data: JSONObject = to_data(self)
        return data


def match_of_job_name(name: str, comment: str = "") -> str | None:
    if comment == ENV_REMOTE_COMMENT or not name.startswith(MATCH_JOB_PREFIX):
        return None
    return name.removeprefix(MATCH_JOB_PREFIX)


_BRACKET = re.compile(r"\[([^\]]*)\]")


def expand_hostlist(text: str) -> list[str]:
    """Slurm's compressed host list as names: ``n[1-3,5],m07`` -> n1 n2 n3 n5 m07 (zero padding
    kept: ``n[01-02]`` -> n01 n02; several brackets in one name give every combination)."""
    names: list[str] = []
    for item in _split_top(text.strip()):
        if not item:
            continue
        parts = _BRACKET.split(item)  # literal, ranges, literal, ranges, ..., literal
        choices: list[list[str]] = []
        for i, part in enumerate(parts):
            choices.append([part] if i % 2 == 0 else _ranges(part, text))
        names.extend("".join(combo) for combo in itertools.product(*choices))
    return names


def _split_top(text: str) -> list[str]:
    """Split at commas outside brackets."""
    items, depth, start = [], 0, 0
    for i, ch in enumerate(text):
        if ch == "[":
            depth += 1
        elif ch == "]":
            depth -= 1
        elif ch == "," and depth == 0:
            items.append(text[start:i])
            start = i + 1
    items.append(text[start:])
    return items


def _ranges(spec: str, text: str) -> list[str]:
    out: list[str] = []
    for part in spec.split(","):
        lo, _, hi = part.partition("-")
        if not lo.isdigit() or (hi and not hi.isdigit()):
            raise ValueError(f"Slurm host list {text!r}: {part!r} is not a number or a range "
                             "like 1-3")
        width = len(lo)
        for n in range(int(lo), int(hi or lo) + 1):
            out.append(str(n).zfill(width))
    return out


def _number(text: str) -> float | None:
    try:
        return float(text)
    except ValueError:
        return None  # N/A


def parse_sinfo(text: str) -> list[PoolNode]:
    """Nodes from ``sinfo -N -h -o SINFO_FORMAT`` (a node in two partitions listed once)."""
    nodes: dict[str, PoolNode] = {}
    for line in text.splitlines():
        if not line.strip():
            continue
        fields = line.split("|", 7)
        if len(fields) != 8:
            raise ValueError(f"sinfo line {line!r}: expected 8 fields separated by '|' "
                             f"({SINFO_FORMAT}), got {len(fields)}")
        name, state, cpus, memory, free, load, features, reason = fields
        counts = cpus.split("/")  # allocated/idle/other/total
        if len(counts) != 4 or not all(c.isdigit() for c in counts):
            raise ValueError(f"sinfo line {line!r}: CPUs {cpus!r}, expected A/I/O/T")
        free_mb = _number(free)
        nodes.setdefault(name, PoolNode(
            name=name, state=state, reason="" if reason.strip() == "none" else reason.strip(),
            features=tuple(f for f in features.split(",") if f and f != "(null)"),
            cpus=int(counts[3]), cpus_allocated=int(counts[0]), cpu_load=_number(load),
            memory_mb=int(_number(memory) or 0),
            memory_free_mb=None if free_mb is None else int(free_mb), slots=1,
        ))  # fmt: skip
    return list(nodes.values())


def parse_squeue_nodes(text: str) -> dict[str, list[NodeJob]]:
    """Jobs per node from ``squeue -h -o SQUEUE_NODES_FORMAT`` (pending jobs have no node)."""
    per_node: dict[str, list[NodeJob]] = {}
    for line in text.splitlines():
        if not line.strip():
            continue
        job_id, name, state, nodelist, comment = (line.split("|", 4) + [""] * 4)[:5]
        if not nodelist.strip() or state == "PENDING":
            continue
        job = NodeJob(job_id=job_id, match_id=match_of_job_name(name, comment), state=state)
        for node in expand_hostlist(nodelist):
            per_node.setdefault(node, []).append(job)
    return per_node


__all__ = [
    "ENV_REMOTE_COMMENT", "NodeJob", "PoolNode", "expand_hostlist", "match_of_job_name",
    "parse_sinfo", "parse_squeue_nodes",
]
