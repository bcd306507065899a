"""What one match's phases are given: the options of a run and the match's dependencies.

:class:`MatchDeps` holds what every phase reads and none replaces: the plan, the engine, the
host, the options, the clock, the event stream observers follow, the telemetry factory and the
containers' stats monitor. The runner (:mod:`orchestrator.match.runner`) builds it once; the
phases (:func:`~orchestrator.match.startup.start`,
:func:`~orchestrator.match.collection.collect`) take it next to what they work on and return
what they produce. This module imports none of them, so there is no import circle between the
runner and its phases.
"""

from __future__ import annotations

import logging
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path

from contracts import Color, StateMessage
from orchestrator.match.events import EventStream, MatchFailed
from orchestrator.match.gpu import SimulatorGpu
from orchestrator.match.host import Host
from orchestrator.match.layout import SIMULATOR_COMMAND
from orchestrator.match.logfs import safe_name
from orchestrator.match.monitor import StatsMonitor
from orchestrator.match.placement import LeaguePlacement
from orchestrator.match.plan import MatchPlan
from orchestrator.match.results import Failure, FailureClass
from orchestrator.paths import user_path
from orchestrator.runtime.port import ContainerRuntime
from orchestrator.telemetry import TelemetrySource

log = logging.getLogger(__name__)

TelemetryFactory = Callable[[str, str], TelemetrySource]  # (endpoint, match_id)


@dataclass(frozen=True, slots=True, kw_only=True)
class RunOptions:
    out_dir: Path
    simulator_image: str
    simulator_command: tuple[str, ...] = SIMULATOR_COMMAND
    holder_image: str | None = None  # default: the simulator image (needs ``sleep``)
    # the robots' start gate (:func:`orchestrator.match.gate.start_gate`; dense placement):
    # None: each robot starts in the network of a holder container
    start_gate: Path | None = None
    extra_labels: Mapping[str, str] = field(default_factory=dict)
    poll_s: float = 0.5
    simulator_stop_s: float = 10.0
    # an engine that stops answering during collection (stopped, restarted) is waited for this
    # long in all, so that the logs it still holds are collected and the match's objects removed
    engine_wait_s: float = 60.0
    progress: Callable[[str, StateMessage | None], None] | None = None
    # league placement: the simulator and each robot on a node of its own (None: dense, the
    # whole match on this host's engine with a network per team)
    placement: LeaguePlacement | None = None
    gpu: SimulatorGpu | None = None  # the host's GPU for the simulator (None: cameras on CPU)

    def __post_init__(self) -> None:
        # The output folder becomes bind-mount sources: Docker takes a relative one for a volume.
        object.__setattr__(self, "out_dir", user_path(self.out_dir))


@dataclass(frozen=True, slots=True, kw_only=True)
class MatchDeps:
    """One match's dependencies: read by every phase, replaced by none (see the module
    docstring). ``events`` and ``monitor`` are sinks the phases report into."""

    plan: MatchPlan
    runtime: ContainerRuntime
    host: Host
    options: RunOptions
    clock: Callable[[], float]
    events: EventStream  # the match's progress, for observers in other threads
    monitor: StatsMonitor  # CPU and memory peaks of the started containers
    telemetry: TelemetryFactory | None = None  # None: the match is watched without telemetry

    @property
    def prefix(self) -> str:
        """The prefix of every container and network name of the match."""
        return f"hlvs-{safe_name(self.plan.match_id)}"

    def fail(self, current: Failure | None, failure_class: FailureClass, cause: str, *,
             team: Color | None = None) -> Failure:
        """The match's failure once this one is recorded: ``current`` when there is one (the
        first failure counts), else the new one (``team``: the team that caused it), published
        (:class:`~orchestrator.match.events.MatchFailed`) and logged."""
        if current is not None:
            return current
        failure = Failure(failure_class=failure_class, cause=cause, team=team)
        self.events.publish(MatchFailed(failure=failure))
        if failure_class is FailureClass.INTERRUPTED:  # asked for (a stop, a pre-flight)
            log.info("match %s stopped: %s", self.plan.match_id, cause)
        else:
            log.error("match %s failed (%s): %s", self.plan.match_id, failure_class.value, cause)
        return failure


__all__ = ["MatchDeps", "RunOptions", "TelemetryFactory"]
