"""The cluster: the match pool, the port through which the service, the schedule, the pooled
commands and the learning environments play matches or run remotes.

A pool takes a prepared match (a ``game.json`` with its team files, in a work folder), plays it
somewhere and leaves the usual match output (``report.json``, ``results.json``, logs) in
``results_dir(handle)``. The service keeps only the handle (a string) in its database, so a pool
must answer ``status`` for handles made by an earlier process: that is how a restarted service
finds the matches that went on while it was down.

Implementations: :class:`cluster.local.LocalDockerPool` (this host's Docker engine, one
``hlvs match`` process per match) and :class:`cluster.slurm.SlurmPool` (one Slurm batch job
per match, ``sbatch`` / ``squeue`` / ``scancel`` in its own adapter module), chosen in
:func:`make_pool`. Errors: :mod:`cluster.errors`.
"""

from __future__ import annotations

import enum
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Protocol

from cluster.errors import ClusterError, PoolError
from cluster.nodes import NodeJob, PoolNode
from contracts import lazy_exports

if TYPE_CHECKING:
    from cluster.local import process_start_time, start_match
    from cluster.nodes import ENV_REMOTE_COMMENT
    from cluster.slurm import HOST_NETNS, SlurmPool


@dataclass(frozen=True, slots=True, kw_only=True)
class MatchJob:
    """One match to play: ``game_path`` references its team files; output goes under
    ``work_dir`` (the pool decides where; see ``results_dir``)."""

    match_id: str
    game_path: Path
    work_dir: Path
    account: str | None = None  # a cluster account the match is charged to (a team's)
    requeue: bool = False  # a cluster may play it again after a node failure (test matches)
    match_args: tuple[str, ...] = ()  # more options of ``hlvs match`` (e.g. ``--grace 3``)
    # league placement: a node of its own for each of this many robots, besides the
    # simulator's node (0: dense placement, the whole match on one node)
    robot_nodes: int = 0


class JobState(enum.StrEnum):
    PENDING = "pending"  # accepted, waiting for resources inside the pool (clusters)
    RUNNING = "running"
    FINISHED = "finished"  # ended, with a report.json in results_dir (whatever the outcome)
    LOST = "lost"  # not running and no report: the pool lost it; it never played to an end


@dataclass(frozen=True, slots=True, kw_only=True)
class JobStatus:
    state: JobState
    detail: str = ""


class MatchPool(Protocol):
    """Port of the match pool (see the module doc). Every method is safe to call again."""

    slots: int
    """Matches the pool plays at once; the service starts no more than that."""

    def submit(self, job: MatchJob) -> str:
        """Start ``job``; returns its handle. Submitting a match id that is already running
        returns the running one's handle instead of starting it twice."""
        ...

    def status(self, handle: str) -> JobStatus: ...

    def cancel(self, handle: str) -> None:
        """Ask the match to stop gracefully (robots get their grace period, logs are
        collected, report.json says ``interrupted``)."""
        ...

    def results_dir(self, handle: str) -> Path: ...

    def nodes(self) -> list[PoolNode]:
        """The pool's machines for operators: state, CPUs, memory, the matches on each."""
        ...


def make_pool(*, kind: str = "local", slots: int, slurm_conf: str | None = None) -> MatchPool:
    """The pool named by ``kind``: ``local`` (this host's Docker engine, ``slots`` matches at
    once) or ``slurm`` (the cluster that ``slurm_conf`` or ``SLURM_CONF`` names, see
    :mod:`cluster.slurm`)."""
    if kind == "slurm":
        from cluster.slurm import HOST_NETNS, SlurmPool

        # on a one-machine cluster (scripts/ensure-slurm.sh) the nodes reach Docker's networks
        # through the host's network namespace
        return SlurmPool(slots=slots, slurm_conf=slurm_conf or None,
                         host_network=Path(HOST_NETNS).exists())
    from cluster.local import LocalDockerPool

    return LocalDockerPool(slots=slots)


__all__ = [
    "ClusterError",
    "ENV_REMOTE_COMMENT",
    "HOST_NETNS",
    "JobState",
    "JobStatus",
    "MatchJob",
    "MatchPool",
    "NodeJob",
    "PoolError",
    "PoolNode",
    "SlurmPool",
    "make_pool",
    "process_start_time",
    "start_match",
]


if not TYPE_CHECKING:
    __getattr__, __dir__ = lazy_exports(__name__, {
        "cluster.local": ("process_start_time", "start_match"),
        "cluster.nodes": ("ENV_REMOTE_COMMENT",),
        "cluster.slurm": ("HOST_NETNS", "SlurmPool"),
    })
