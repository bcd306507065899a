"""A robot outside the turf (field plus border strip) for more than 20 s is removed."""

from __future__ import annotations

from dataclasses import dataclass, field

from contracts import RobotId
from referee.gamecontroller.states import GameState, Penalty
from referee.rules.base import Decision, GameView, PenalizeRobot, timers
from referee.snapshot import RobotState, WorldSnapshot

JUDGED_STATES = frozenset({GameState.READY, GameState.SET, GameState.PLAYING})


@dataclass(frozen=True, slots=True)
class OutsideTurfMemory:
    since_ms: dict[RobotId, int] = field(default_factory=dict)


def outside_turf(robot: RobotState, game: GameView) -> bool:
    x, y = robot.position[0], robot.position[1]
    return abs(x) > game.field.turf_half_length_m or abs(y) > game.field.turf_half_width_m


def judge(
    snapshot: WorldSnapshot, game: GameView, memory: OutsideTurfMemory
) -> tuple[list[Decision], OutsideTurfMemory]:
    if game.state not in JUDGED_STATES:
        return [], OutsideTurfMemory()
    outside = [r.id for r in snapshot.robots if game.active(r) and outside_turf(r, game)]
    expired, kept = timers(
        outside, memory.since_ms, snapshot.sim_time_ms, game.timing.outside_turf_s
    )
    decisions: list[Decision] = [
        PenalizeRobot(robot, Penalty.PICKUP_OR_INCAPABLE, "left the turf") for robot in expired
    ]
    return decisions, OutsideTurfMemory(kept)
