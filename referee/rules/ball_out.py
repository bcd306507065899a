"""Ball out of the field: throw-in over a touch line, goal kick or corner kick over a goal line.

The ball is out when it is fully beyond the outer edge of the line (the lines belong to the
field). Throw-in: for the opponents of the last toucher, ball on the touch line at the x where it
left. Goal line: corner kick (at the corner on the side where it left) when a defender touched
it last, otherwise goal kick (ball where the halfway line meets the touch line on that side, as
the league's referee places it). Every spot is on the middle of its line, as the league's
referee puts it. Without any recorded touch the team defending the half the ball left from gets
the restart.
"""

from __future__ import annotations

import math

from contracts import FieldGeometry
from referee.gamecontroller.states import SecondaryState
from referee.rules.base import AwardSetPlay, Decision, GameView
from referee.snapshot import Vec2, WorldSnapshot


def _sign(value: float) -> float:
    return -1.0 if value < 0 else 1.0


def over_touch_line(position: tuple[float, float, float], field: FieldGeometry) -> bool:
    return abs(position[1]) - field.ball_radius_m > field.half_width_m


def over_goal_line(position: tuple[float, float, float], field: FieldGeometry) -> bool:
    return abs(position[0]) - field.ball_radius_m > field.half_length_m


def in_goal(position: tuple[float, float, float], field: FieldGeometry) -> bool:
    """Fully over a goal line, between the posts and under the bar."""
    return (
        over_goal_line(position, field)
        and abs(position[1]) < field.goal_width_m / 2.0
        and position[2] < field.goal_height_m
    )


def on_line(field: FieldGeometry) -> float:
    """How far in from the field's edge a set play's ball is put: the middle of the line, as
    the league's referee puts it (``size - line_half_width``, hlvs_webots referee.py:1731,
    1740-1751)."""
    return field.line_width_m / 2.0


def corner_spot(goal_sign: float, y_sign: float, field: FieldGeometry) -> Vec2:
    inset = on_line(field)
    return (goal_sign * (field.half_length_m - inset), y_sign * (field.half_width_m - inset))


def goal_kick_spot(goal_sign: float, y_sign: float, field: FieldGeometry) -> Vec2:
    """Where the halfway line meets the touch line on the side the ball left, as the league's
    referee places a goal kick's ball (hlvs_webots referee.py:1747-1752, ``goal_kick``)."""
    del goal_sign  # the same spot whichever goal line the ball crossed
    return (0.0, y_sign * (field.half_width_m - on_line(field)))


def goal_line_restart(
    snapshot: WorldSnapshot, game: GameView, goal_sign: float, reason: str
) -> AwardSetPlay:
    field = game.field
    defending = game.team_on_side(goal_sign)
    toucher = snapshot.last_ball_toucher
    y_sign = _sign(snapshot.ball.position[1])
    if toucher is not None and toucher.team is defending:
        spot = corner_spot(goal_sign, y_sign, field)
        return AwardSetPlay(SecondaryState.CORNER_KICK, defending.opponent, spot, reason)
    spot = goal_kick_spot(goal_sign, y_sign, field)
    return AwardSetPlay(SecondaryState.GOAL_KICK, defending, spot, reason)


def judge(snapshot: WorldSnapshot, game: GameView) -> list[Decision]:
    if not game.running:
        return []
    field = game.field
    position = snapshot.ball.position
    if over_touch_line(position, field):
        toucher = snapshot.last_ball_toucher
        team = (
            toucher.team.opponent
            if toucher is not None
            else game.team_on_side(_sign(position[0]))
        )
        x = max(-field.half_length_m, min(field.half_length_m, position[0]))
        y = math.copysign(field.half_width_m - on_line(field), position[1])
        return [AwardSetPlay(SecondaryState.THROW_IN, team, (x, y), "ball over the touch line")]
    if over_goal_line(position, field) and not in_goal(position, field):
        return [goal_line_restart(snapshot, game, _sign(position[0]), "ball over the goal line")]
    return []
