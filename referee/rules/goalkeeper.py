"""Inactive goalkeeper: a goalkeeper in its own goal area with the ball within 0.5 m for 20 s
(configurable) without getting 5 cm closer to it is removed (INCAPABLE)."""

from __future__ import annotations

from dataclasses import dataclass, field

from contracts import RobotId
from referee.gamecontroller.states import Penalty
from referee.rules.base import Decision, GameView, PenalizeRobot, distance2d
from referee.snapshot import RobotState, WorldSnapshot

BALL_NEAR_M = 0.5
PROGRESS_M = 0.05


@dataclass(frozen=True, slots=True)
class GoalkeeperMemory:
    watch: dict[RobotId, tuple[int, float]] = field(default_factory=dict)  # since, best dist


def in_own_goal_area(robot: RobotState, game: GameView) -> bool:
    field_ = game.field
    sign = game.side_sign(robot.id.team)
    x, y = robot.position[0] * sign, robot.position[1]
    return (
        field_.half_length_m - field_.goal_area_length_m <= x <= field_.half_length_m + 0.5
        and abs(y) <= field_.goal_area_width_m / 2.0
    )


def judge(
    snapshot: WorldSnapshot, game: GameView, memory: GoalkeeperMemory
) -> tuple[list[Decision], GoalkeeperMemory]:
    if not game.running:
        return [], GoalkeeperMemory()
    now = snapshot.sim_time_ms
    decisions: list[Decision] = []
    watch: dict[RobotId, tuple[int, float]] = {}
    for robot in snapshot.robots:
        if robot.id not in game.goalkeepers or not game.active(robot):
            continue
        dist = distance2d(robot.position, snapshot.ball.position)
        if dist > BALL_NEAR_M or not in_own_goal_area(robot, game):
            continue
        since, best = memory.watch.get(robot.id, (now, dist))
        if dist < best - PROGRESS_M:
            since, best = now, dist
        if now - since > game.timing.inactive_goalkeeper_s * 1000.0:
            decisions.append(
                PenalizeRobot(robot.id, Penalty.PICKUP_OR_INCAPABLE, "inactive goalkeeper")
            )
            continue
        watch[robot.id] = (since, best)
    return decisions, GoalkeeperMemory(watch)
