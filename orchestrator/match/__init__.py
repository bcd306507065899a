"""One match in real containers: plan, lifecycle, runner, results, cleanup.

Domain code: it talks to the engine only through :class:`ContainerRuntime` and to the host only
through :class:`Host`; ``hlvs.commands.match`` wires the real implementations.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from contracts import lazy_exports
from orchestrator.match.cleanup import CleanupReport, clean_match, cleanup, plan_cleanup
from orchestrator.match.events import (
    AllConnected,
    EventStream,
    MatchEnded,
    MatchEvent,
    MatchFailed,
    RobotExited,
    RobotNotStarted,
    StateChanged,
)
from orchestrator.match.gate import start_gate
from orchestrator.match.host import Host, HostControl
from orchestrator.match.plan import (
    MatchPlan,
    RegistryAccess,
    RobotPlan,
    TeamPlan,
    plan_from_game,
    robots_in_game,
)
from orchestrator.match.results import Failure, FailureClass, RobotRecord
from orchestrator.match.runner import (
    ImageResolver,
    MatchOutcome,
    MatchRunner,
    RunOptions,
    local_images,
)
from orchestrator.match.state import IllegalMatchTransition, Lifecycle, MatchState
from orchestrator.runtime.port import ContainerRuntime

if TYPE_CHECKING:
    from orchestrator.match import ownership, scrimmage
    from orchestrator.match.admission import HostResources, admit
    from orchestrator.match.gpu import GpuOrigin, SimulatorGpu, simulator_gpu
    from orchestrator.match.ownership import LABEL_RUN
    from orchestrator.match.placement import LeaguePlacement, parse_nodes
    from orchestrator.match.robot_runtime import check_robot_runtime
    from orchestrator.match.scrimmage import ScrimmageRequest, game_file, team_file

__all__ = [
    "AllConnected",
    "CleanupReport",
    "ContainerRuntime",
    "EventStream",
    "Failure",
    "FailureClass",
    "GpuOrigin",
    "Host",
    "HostControl",
    "HostResources",
    "IllegalMatchTransition",
    "ImageResolver",
    "LABEL_RUN",
    "LeaguePlacement",
    "Lifecycle",
    "MatchEnded",
    "MatchEvent",
    "MatchFailed",
    "MatchOutcome",
    "MatchPlan",
    "MatchRunner",
    "MatchState",
    "RegistryAccess",
    "RobotExited",
    "RobotNotStarted",
    "RobotPlan",
    "RobotRecord",
    "RunOptions",
    "start_gate",
    "ScrimmageRequest",
    "SimulatorGpu",
    "StateChanged",
    "TeamPlan",
    "admit",
    "check_robot_runtime",
    "clean_match",
    "cleanup",
    "game_file",
    "local_images",
    "ownership",
    "parse_nodes",
    "plan_cleanup",
    "plan_from_game",
    "robots_in_game",
    "scrimmage",
    "simulator_gpu",
    "team_file",
]


if not TYPE_CHECKING:
    __getattr__, __dir__ = lazy_exports(__name__, {
        "orchestrator.match": ("ownership", "scrimmage"),
        "orchestrator.match.admission": ("HostResources", "admit"),
        "orchestrator.match.gpu": ("GpuOrigin", "SimulatorGpu", "simulator_gpu"),
        "orchestrator.match.ownership": ("LABEL_RUN",),
        "orchestrator.match.placement": ("LeaguePlacement", "parse_nodes"),
        "orchestrator.match.robot_runtime": ("check_robot_runtime",),
        "orchestrator.match.scrimmage": ("ScrimmageRequest", "game_file", "team_file"),
    })
