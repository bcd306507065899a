"""The state one match's phases share: the plan, the engine, what was created, the outcome.

:class:`MatchContext` is what the runner (:mod:`orchestrator.match.runner`) and its phases
(:class:`~orchestrator.match.startup.StartupPhase`,
:class:`~orchestrator.match.collection.CollectionPhase`) work on: a phase gets the context, records
what it created in :attr:`MatchContext.started` (so that teardown removes exactly that) and
reports failures with :meth:`MatchContext.fail`. This module imports none of them, so there is no
import circle between the runner and its phases. Observers in other threads subscribe to
:attr:`MatchContext.events` (:mod:`orchestrator.match.events`) rather than read its fields.
"""

from __future__ import annotations

import logging
import threading
import time
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path

from contracts import Color, Forfeit, StateMessage
from orchestrator.bandwidth import AppliedShaping
from orchestrator.match.admission import CpuSets
from orchestrator.match.events import EventStream, MatchFailed, StateChanged
from orchestrator.match.gpu import SimulatorGpu
from orchestrator.match.host import Host
from orchestrator.match.layout import SIMULATOR_COMMAND, Subnet
from orchestrator.match.logfs import LogFolder
from orchestrator.match.monitor import StatsMonitor
from orchestrator.match.placement import LeaguePlacement
from orchestrator.match.plan import MatchPlan
from orchestrator.match.results import Failure, FailureClass, RobotRecord
from orchestrator.match.runtime import ContainerRuntime, NetworkInfo
from orchestrator.match.state import Lifecycle, MatchState
from orchestrator.paths import user_path
from orchestrator.telemetry import TelemetrySource

log = logging.getLogger(__name__)

TelemetryFactory = Callable[[str, str], TelemetrySource]  # (endpoint, match_id)


@dataclass(frozen=True, slots=True, kw_only=True)
class RunOptions:
    out_dir: Path
    simulator_image: str
    simulator_command: tuple[str, ...] = SIMULATOR_COMMAND
    holder_image: str | None = None  # default: the simulator image (needs ``sleep``)
    extra_labels: Mapping[str, str] = field(default_factory=dict)
    poll_s: float = 0.5
    simulator_stop_s: float = 10.0
    progress: Callable[[str, StateMessage | None], None] | None = None
    # league placement: the simulator and each robot on a node of its own (None: dense, the
    # whole match on this host's engine with a network per team)
    placement: LeaguePlacement | None = None
    gpu: SimulatorGpu | None = None  # the host's GPU for the simulator (None: cameras on CPU)

    def __post_init__(self) -> None:
        # The output folder becomes bind-mount sources: Docker takes a relative one for a volume.
        object.__setattr__(self, "out_dir", user_path(self.out_dir))


@dataclass(slots=True)
class Started:
    """Everything created so far, so that teardown removes exactly that."""

    prefix: str = ""
    networks: dict[str, NetworkInfo] = field(default_factory=dict)  # role -> network
    subnets: dict[str, Subnet] = field(default_factory=dict)
    simulator_id: str | None = None
    simulator_started_at: float = 0.0
    holder_ids: dict[str, str] = field(default_factory=dict)  # robot key -> holder id
    robot_ids: dict[str, str] = field(default_factory=dict)  # robot key -> container id
    shaping: dict[str, AppliedShaping] = field(default_factory=dict)
    log_folders: dict[str, LogFolder] = field(default_factory=dict)
    scratch: dict[str, LogFolder] = field(default_factory=dict)  # robot key -> scratch space
    cpu_sets: CpuSets = field(default_factory=lambda: CpuSets(simulator=None, robots=None))
    match_dir: Path | None = None
    # bring-up breakdown: seconds per phase of STARTING, and per robot and step of its start
    phases_s: dict[str, float] = field(default_factory=dict)
    robot_steps_s: dict[str, dict[str, float]] = field(default_factory=dict)
    # league placement: robot node firewalls made (node netns, None: this network) and the
    # shaping of robot nodes' interfaces (the nodes outlive the match: both are undone)
    node_firewalls: list[str | None] = field(default_factory=list)
    node_shaping: list[AppliedShaping] = field(default_factory=list)


class MatchContext:
    """One match's shared state; see the module docstring."""

    def __init__(
        self,
        plan: MatchPlan,
        *,
        runtime: ContainerRuntime,
        host: Host,
        options: RunOptions,
        telemetry: TelemetryFactory | None = None,
        stop_event: threading.Event | None = None,
        clock: Callable[[], float] = time.monotonic,
    ) -> None:
        self.plan = plan
        self.runtime = runtime
        self.host = host
        self.options = options
        self.telemetry_factory = telemetry
        self.stop_event = stop_event or threading.Event()
        self.clock = clock
        self.lifecycle = Lifecycle(plan.match_id, clock=clock)
        self.records = {
            r.key: RobotRecord(key=r.key, color=r.color, number=r.number, image=r.image)
            for r in plan.robots
        }
        self.monitor = StatsMonitor(runtime)
        self.started = Started()
        self.failure: Failure | None = None
        self.forfeit: Forfeit | None = None
        self.bringup_s: float | None = None
        self.telemetry: TelemetrySource | None = None
        # the teams' logs cut or lost in collection: {"robot", "what", "reason"} (report.json)
        self.logs_cut: list[dict[str, str]] = []
        self.events = EventStream()  # the match's progress, for observers in other threads


    def advance(self, target: MatchState) -> None:
        """Move the match to ``target`` (the lifecycle checks the transition)."""
        self.lifecycle.advance(target)
        self.events.publish(StateChanged(state=self.lifecycle.state))
        self.progress(None)

    def progress(self, state: StateMessage | None) -> None:
        if self.options.progress is not None:
            self.options.progress(self.lifecycle.state.value, state)

    def fail(self, failure_class: FailureClass, cause: str, *, team: Color | None = None
             ) -> None:
        """Record the match's failure (``team``: the team that caused it); the first counts."""
        if self.failure is None:
            self.failure = Failure(failure_class=failure_class, cause=cause, team=team)
            self.events.publish(MatchFailed(failure=self.failure))
            if failure_class is FailureClass.INTERRUPTED:  # asked for (a stop, a pre-flight)
                log.info("match %s stopped: %s", self.plan.match_id, cause)
            else:
                log.error("match %s failed (%s): %s", self.plan.match_id, failure_class.value,
                          cause)


__all__ = ["MatchContext", "RunOptions", "Started", "TelemetryFactory"]
