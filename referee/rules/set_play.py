"""Set-play compliance: when a set play is executed, opponents of the executing team closer to
the ball than the opponent distance (0.75 m kid, 1.5 m adult) are removed (INCAPABLE)."""

from __future__ import annotations

from referee.gamecontroller.machine import SetPlay
from referee.gamecontroller.states import Penalty
from referee.rules.base import Decision, GameView, PenalizeRobot, distance2d
from referee.snapshot import WorldSnapshot


def judge_execute(snapshot: WorldSnapshot, game: GameView, play: SetPlay) -> list[Decision]:
    limit = game.field.opponent_distance_m
    reason = f"closer than {limit:g} m to the ball at the {play.kind.name.lower()}"
    return [
        PenalizeRobot(robot.id, Penalty.PICKUP_OR_INCAPABLE, reason)
        for robot in snapshot.robots
        if robot.id.team is not play.team
        and game.active(robot)
        and distance2d(robot.position, snapshot.ball.position) < limit
    ]
