"""A robot that stays fallen longer than 20 s (configurable) is removed as INCAPABLE."""

from __future__ import annotations

from dataclasses import dataclass, field

from contracts import RobotId
from referee.gamecontroller.states import GameState, Penalty, SecondaryState
from referee.rules.base import Decision, GameView, PenalizeRobot, timers
from referee.snapshot import WorldSnapshot

JUDGED_STATES = frozenset({GameState.READY, GameState.SET, GameState.PLAYING})


@dataclass(frozen=True, slots=True)
class FallenMemory:
    since_ms: dict[RobotId, int] = field(default_factory=dict)


def judge(
    snapshot: WorldSnapshot, game: GameView, memory: FallenMemory
) -> tuple[list[Decision], FallenMemory]:
    if game.state not in JUDGED_STATES or game.phase is SecondaryState.PENALTYSHOOT:
        return [], FallenMemory()
    fallen = [r.id for r in snapshot.robots if r.fallen and game.active(r)]
    expired, kept = timers(fallen, memory.since_ms, snapshot.sim_time_ms, game.timing.fallen_s)
    decisions: list[Decision] = [
        PenalizeRobot(robot, Penalty.PICKUP_OR_INCAPABLE, "fallen down") for robot in expired
    ]
    return decisions, FallenMemory(kept)
