"""One match in real containers: plan, lifecycle, runner, results, cleanup.

Domain code: it talks to the engine only through :class:`ContainerRuntime` and to the host only
through :class:`Host`; ``hlvs.commands.match`` wires the real implementations.
"""

from __future__ import annotations

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
from orchestrator.match.host import Host, HostControl
from orchestrator.match.plan import MatchPlan, RobotPlan, TeamPlan, plan_from_game, robots_in_game
from orchestrator.match.results import Failure, FailureClass, RobotRecord
from orchestrator.match.runner import (
    ImageResolver,
    MatchOutcome,
    MatchRunner,
    RunOptions,
    local_images,
)
from orchestrator.match.runtime import ContainerRuntime
from orchestrator.match.state import IllegalMatchTransition, Lifecycle, MatchState

__all__ = [
    "AllConnected",
    "CleanupReport",
    "ContainerRuntime",
    "EventStream",
    "Failure",
    "FailureClass",
    "Host",
    "HostControl",
    "IllegalMatchTransition",
    "ImageResolver",
    "Lifecycle",
    "MatchEnded",
    "MatchEvent",
    "MatchFailed",
    "MatchOutcome",
    "MatchPlan",
    "MatchRunner",
    "MatchState",
    "RobotExited",
    "RobotNotStarted",
    "RobotPlan",
    "RobotRecord",
    "RunOptions",
    "StateChanged",
    "TeamPlan",
    "clean_match",
    "cleanup",
    "local_images",
    "plan_cleanup",
    "plan_from_game",
    "robots_in_game",
]
