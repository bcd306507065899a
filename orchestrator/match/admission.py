"""Admission: does a match fit the machine it is about to run on?

The robots' CPU and memory limits plus what the simulator needs (:data:`SIMULATOR_CPUS`,
:data:`SIMULATOR_MEMORY_GB`) are compared with what the host (or the pool node) has. An official
match that does not fit is refused with the numbers; any other match (a scrimmage, a test match)
is played with a warning recorded in ``results.json`` (``admission``). Whatever the verdict, the
simulator container gets :data:`SIMULATOR_CPU_SHARES` (robots keep Docker's 1024), so under
contention the kernel gives it its share first, and in async stepping on a local engine with
more CPUs than the simulator needs the CPUs are split (:func:`cpu_sets`): the simulator's own,
which no robot may use (with the spare CPUs for its camera render processes when the cameras
render on the CPU), and the robots'. A team cannot starve the simulator.
"""

from __future__ import annotations

import logging
import math
import os
from dataclasses import dataclass, replace
from pathlib import Path

from contracts import AdmissionRecord, JSONObject, NeededAvailable, to_data
from orchestrator.errors import OrchestratorError
from orchestrator.match.plan import MatchPlan

log = logging.getLogger(__name__)

SIMULATOR_CPUS = 1.0  # the step thread needs a core of its own
SIMULATOR_MEMORY_GB = 2.0
SIMULATOR_CPU_SHARES = 8192  # 8x a robot's weight when CPUs are contended


@dataclass(frozen=True, slots=True, kw_only=True)
class HostResources:
    cpus: float
    memory_gb: float
    name: str = "this host"

    @classmethod
    def local(cls) -> HostResources:
        """The CPUs this process may run on and the machine's memory."""
        cpus = float(len(os.sched_getaffinity(0)))
        memory_gb = 0.0
        try:
            for line in Path("/proc/meminfo").read_text().splitlines():
                if line.startswith("MemTotal:"):
                    memory_gb = int(line.split()[1]) * 1024 / 1e9
                    break
        except OSError:
            pass
        return cls(cpus=cpus, memory_gb=memory_gb)


@dataclass(frozen=True, slots=True, kw_only=True)
class Admission:
    official: bool
    fits: bool
    robots: int
    needed_cpus: float
    available_cpus: float
    needed_memory_gb: float
    available_memory_gb: float
    host: str

    def shortfall(self) -> str:
        """The numbers, e.g. ``CPUs: 8 robots x 4 + simulator 1 = 33 > 2 on this host``."""
        parts = []
        if self.needed_cpus > self.available_cpus:
            parts.append(f"CPUs needed {self.needed_cpus:g} (robots' limits + simulator "
                         f"{SIMULATOR_CPUS:g}) > {self.available_cpus:g} available")
        if self.needed_memory_gb > self.available_memory_gb:
            parts.append(f"memory needed {self.needed_memory_gb:g} GB (robots' limits + "
                         f"simulator {SIMULATOR_MEMORY_GB:g} GB) > "
                         f"{self.available_memory_gb:.1f} GB available")
        return "; ".join(parts)

    def record(self) -> AdmissionRecord:
        """What ``results.json`` keeps of the verdict."""
        return AdmissionRecord(
            official=self.official, fits=self.fits, host=self.host, robots=self.robots,
            cpus=NeededAvailable(needed=self.needed_cpus, available=self.available_cpus),
            memory_gb=NeededAvailable(needed=round(self.needed_memory_gb, 3),
                                      available=round(self.available_memory_gb, 3)),
            simulator_cpu_shares=SIMULATOR_CPU_SHARES,
            warning=None if self.fits else
            f"the match does not fit {self.host}: {self.shortfall()}; played anyway (not "
            "official), so speeds and results may suffer",
        )

    def to_json(self) -> JSONObject:
        """The admission record as JSON (contracts.match_results.AdmissionRecord)."""
        data: JSONObject = to_data(self.record())
        return data


@dataclass(frozen=True, slots=True, kw_only=True)
class CpuSets:
    simulator: str | None  # cpuset of the simulator container (None: no pinning)
    robots: str | None  # cpuset of every robot container


def cpu_sets(*, stepping: str = "async", robot_cpus: float = 0.0,
             render_cpus: int = 0) -> CpuSets:
    """In ``async`` stepping (the league's: the simulation never waits), the first
    ``ceil(SIMULATOR_CPUS)`` CPUs this process may use go to the simulator, the rest to the
    robots. No pinning in ``lockstep`` (simulator and robots take turns, so they share every
    CPU best, and results do not depend on speed), with a remote engine (``DOCKER_HOST`` not a
    local socket) or when no CPU would be left for the robots.

    ``render_cpus``: the robot cameras render (on the CPU or a GPU) in up to that many worker
    processes of the simulator (one per CPU it may use): the CPUs the robots' limits
    (``robot_cpus`` in all) leave spare go to the simulator too, up to ``render_cpus`` more.
    The robots' CPUs are never given away: on a machine without spare CPUs the cameras render
    on the simulator's."""
    remote = os.environ.get("DOCKER_HOST", "unix://")
    allowed = sorted(os.sched_getaffinity(0))
    reserved = math.ceil(SIMULATOR_CPUS)
    spare = len(allowed) - reserved - math.ceil(robot_cpus - 1e-9)
    reserved += max(0, min(render_cpus, spare))
    if stepping != "async" or not remote.startswith("unix://") or len(allowed) <= reserved:
        return CpuSets(simulator=None, robots=None)
    return CpuSets(simulator=",".join(map(str, allowed[:reserved])),
                   robots=",".join(map(str, allowed[reserved:])))


class AdmissionRefused(OrchestratorError):
    def __init__(self, admission: Admission, match_id: str) -> None:
        self.admission = admission
        self.match_id = match_id
        super().__init__(
            f"official match {match_id} refused: it does not fit {admission.host}: "
            f"{admission.shortfall()}; lower limits.cpus / limits.memory_gb in game.json or "
            "run it on a larger machine"
        )


def admit(plan: MatchPlan, *, host: HostResources, official: bool) -> Admission:
    """The verdict for ``plan``; raises :class:`AdmissionRefused` for an official match that
    does not fit."""
    robots = len(plan.robots)
    limits = plan.limits
    admission = Admission(
        official=official, robots=robots, host=host.name,
        needed_cpus=round(robots * limits.cpus + SIMULATOR_CPUS, 3),
        available_cpus=host.cpus,
        needed_memory_gb=robots * limits.memory_gb + SIMULATOR_MEMORY_GB,
        available_memory_gb=host.memory_gb,
        fits=False,
    )
    fits = (admission.needed_cpus <= host.cpus + 1e-9
            and admission.needed_memory_gb <= host.memory_gb + 1e-9)
    admission = replace(admission, fits=fits)
    if not fits:
        if official:
            raise AdmissionRefused(admission, plan.match_id)
        log.warning("match %s: %s", plan.match_id, admission.record().warning)
    return admission


__all__ = [
    "Admission", "AdmissionRefused", "CpuSets", "HostResources", "SIMULATOR_CPUS",
    "SIMULATOR_CPU_SHARES", "SIMULATOR_MEMORY_GB", "admit", "cpu_sets",
]
