"""Start positions, kick-off positions and the kick-off before the ball is in play.

When a period's READY begins, robots at their start positions must stand fully outside the
field on their own side; illegally placed robots are removed (INCAPABLE).

Through SET (checked every step, as the league's referee checks them, hlvs_webots
referee.py:2358-2365) every robot must be inside the field, in its own half, and robots of the
defending team (all robots after a dropped ball) outside the centre circle; illegally placed
robots are removed (INCAPABLE). Until the ball is in play, a defending robot
that enters the centre circle or touches the ball is removed too.
"""

from __future__ import annotations

from referee.gamecontroller.states import Penalty
from referee.rules.base import Decision, GameView, PenalizeRobot, distance2d
from referee.snapshot import RobotState, WorldSnapshot

TOLERANCE_M = 0.05  # a line's width: standing on the line counts as inside


def _illegal_position(robot: RobotState, game: GameView) -> str | None:
    field = game.field
    x, y = robot.position[0], robot.position[1]
    if abs(x) > field.half_length_m + TOLERANCE_M or abs(y) > field.half_width_m + TOLERANCE_M:
        return "outside the field at kick-off"
    if x * game.side_sign(robot.id.team) < -TOLERANCE_M:
        return "in the opponents' half at kick-off"
    defending = game.kickoff_team is None or robot.id.team is not game.kickoff_team
    if defending and distance2d(robot.position, (0.0, 0.0)) < field.centre_circle_radius_m:
        return "inside the centre circle at the opponents' kick-off"
    return None


def judge_start(snapshot: WorldSnapshot, game: GameView) -> list[Decision]:
    """The game goes to READY at the start of a period: a robot at its ``halfTimeStartingPose``
    must stand fully outside the field and fully on its own side of the halfway line, else it
    is removed (INCAPABLE), as the league's referee checks it then (hlvs_webots referee.py:
    1212-1228, ``check_start_position``, with 746-772). The league reads the contacts of the
    feet with the ground, which Webots puts at the corners of the foot boxes (686-770; one on a
    line is on the field, ``field.py`` ``point_inside``); here the soles' corners
    (:meth:`~referee.snapshot.RobotState.sole_corners`), with the torso and the hands and feet
    (``hull_points``): one of them on the field, lines included, or beyond the middle of the
    halfway line is enough. A robot at y 3.02 facing the field has its toes 5 cm further in,
    on the touch line."""
    field = game.field
    half_line = field.line_width_m / 2.0
    decisions: list[Decision] = []
    for robot in snapshot.robots:
        if not game.active(robot):
            continue
        points = [(robot.position[0], robot.position[1]), *robot.hull_points,
                  *robot.sole_corners()]  # fmt: skip
        sign = game.side_sign(robot.id.team)
        reason = None
        if any(abs(x) <= field.half_length_m and abs(y) <= field.half_width_m for x, y in points):
            reason = "halfTimeStartingPose inside the field"
        elif any(x * sign < half_line for x, _ in points):
            reason = "halfTimeStartingPose outside its team's side"
        if reason is not None:
            decisions.append(PenalizeRobot(robot.id, Penalty.PICKUP_OR_INCAPABLE, reason))
    return decisions


def judge_set(snapshot: WorldSnapshot, game: GameView) -> list[Decision]:
    """Called when SET begins and on every step of SET (kick-off or dropped ball)."""
    decisions: list[Decision] = []
    for robot in snapshot.robots:
        if not game.active(robot):
            continue
        reason = _illegal_position(robot, game)
        if reason is not None:
            decisions.append(PenalizeRobot(robot.id, Penalty.PICKUP_OR_INCAPABLE, reason))
    return decisions


def judge_before_in_play(snapshot: WorldSnapshot, game: GameView) -> list[Decision]:
    """PLAYING after a kick-off, until the ball is in play."""
    if not game.running or game.ball_in_play or game.kickoff_team is None:
        return []
    decisions: list[Decision] = []
    radius = game.field.centre_circle_radius_m
    for robot in snapshot.robots:
        if robot.id.team is game.kickoff_team or not game.active(robot):
            continue
        if robot.ball_contacts:
            reason = "touched the ball before it was in play"
        elif distance2d(robot.position, (0.0, 0.0)) < radius:
            reason = "entered the centre circle before the ball was in play"
        else:
            continue
        decisions.append(PenalizeRobot(robot.id, Penalty.PICKUP_OR_INCAPABLE, reason))
    return decisions
