"""Decisions of the stub robot: what to do this tick, from the game state and its beliefs.

Pure functions of plain data (no I/O), so the same code runs in a match and in the bench.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from enum import StrEnum

from simulator.stub.world_model import Pose2D


class Role(StrEnum):
    STRIKER = "striker"
    GOALIE = "goalie"
    IDLE = "idle"


class Phase(StrEnum):
    INITIAL = "INITIAL"
    READY = "READY"
    SET = "SET"
    PLAYING = "PLAYING"
    FINISHED = "FINISHED"


@dataclass(frozen=True, slots=True, kw_only=True)
class GameInfo:
    phase: Phase
    penalised: bool = False
    our_kick_off: bool = True
    first_half: bool = True
    ball_free_in_s: float = 0.0  # PLAYING: the opponents' kick-off is still protected this long


@dataclass(frozen=True, slots=True, kw_only=True)
class Action:
    """Walk with (vx m/s, vy m/s, vyaw rad/s), or kick with ``kick_foot``, or stand."""

    walk: tuple[float, float, float] = (0.0, 0.0, 0.0)
    kick_foot: str | None = None
    search: bool = False  # scan with the head

    @property
    def stands(self) -> bool:
        return self.kick_foot is None and self.walk == (0.0, 0.0, 0.0)


STAND = Action()


@dataclass(frozen=True, slots=True, kw_only=True)
class Field:
    half_length_m: float
    foot_y_m: float  # lateral distance of each foot from the centre line
    kick_x_m: float  # best ball distance in front of the pelvis for a kick


def decide(
    *,
    role: Role,
    game: GameInfo,
    pose: Pose2D,
    ball: tuple[float, float] | None,
    field: Field,
    searching_s: float,
) -> Action:
    """``ball`` is relative to the robot (x forward, y left) or None when not seen lately;
    ``searching_s`` how long the ball has been missing."""
    if role is Role.IDLE or game.penalised or game.phase in (Phase.INITIAL, Phase.SET):
        return STAND
    if game.phase is Phase.FINISHED:
        return STAND
    if game.phase is Phase.READY:
        return _go_to(pose, _kick_off_position(role, game, field))
    # PLAYING
    if not game.our_kick_off and game.ball_free_in_s > 0:
        return STAND  # the opponents' kick-off: keep out of the centre circle
    if role is Role.GOALIE:
        return _goalie(pose, ball, field, searching_s)
    return _striker(pose, ball, field, searching_s)


def _kick_off_position(role: Role, game: GameInfo, field: Field) -> Pose2D:
    if role is Role.GOALIE:
        return Pose2D(-field.half_length_m + 0.5, 0.0, 0.0)
    return Pose2D(-0.35 if game.our_kick_off else -1.0, 0.0, 0.0)


def _go_to(pose: Pose2D, target: Pose2D, *, tolerance_m: float = 0.2) -> Action:
    x, y = pose.to_relative(target.x_m, target.y_m)
    distance = math.hypot(x, y)
    if distance < tolerance_m:
        error = _wrap(target.yaw_rad - pose.yaw_rad)
        if abs(error) < 0.2:
            return STAND
        return Action(walk=(0.0, 0.0, _clip(1.2 * error, 0.5)))
    bearing = math.atan2(y, x)
    forward = 0.15 if abs(bearing) < 0.35 else 0.0
    return Action(walk=(forward, 0.0, _clip(1.5 * bearing, 0.6)))


def _striker(
    pose: Pose2D, ball: tuple[float, float] | None, field: Field, searching_s: float
) -> Action:
    if ball is None:
        return _search(searching_s)
    bx, by = ball
    distance = math.hypot(bx, by)
    bearing = math.atan2(by, bx)
    # direction from the ball to the opponent goal, relative to the robot's heading
    ball_field = pose.to_field(bx, by)
    goal_dir = math.atan2(0.0 - ball_field[1], field.half_length_m - ball_field[0])
    heading_error = _wrap(goal_dir - pose.yaw_rad)
    if distance > 0.55:
        forward = 0.15 if abs(bearing) < 0.3 else (0.06 if abs(bearing) < 0.7 else 0.0)
        return Action(walk=(forward, 0.0, _clip(1.5 * bearing, 0.6)))
    if abs(heading_error) > 0.35:
        # circle around the ball: side-step while turning, keep about 0.3 m away
        return Action(
            walk=(
                _clip(0.8 * (distance - 0.3), 0.06),
                _clip(-0.15 * math.copysign(1.0, heading_error), 0.05),
                _clip(0.8 * heading_error + 0.8 * bearing, 0.5),
            )
        )
    foot = "left" if by > 0 else "right"
    target_y = field.foot_y_m if foot == "left" else -field.foot_y_m
    ex, ey = bx - field.kick_x_m, by - target_y
    if abs(ex) < 0.04 and abs(ey) < 0.025:
        return Action(kick_foot=foot)
    return Action(
        walk=(
            _clip(0.8 * ex, 0.08, low=-0.05),
            _clip(1.2 * ey, 0.05),
            _clip(0.8 * heading_error, 0.3),
        )
    )


def _goalie(
    pose: Pose2D, ball: tuple[float, float] | None, field: Field, searching_s: float
) -> Action:
    home = Pose2D(-field.half_length_m + 0.5, 0.0, 0.0)
    hx, hy = pose.to_relative(home.x_m, home.y_m)
    if math.hypot(hx, hy) > 0.5:
        return _go_to(pose, home, tolerance_m=0.3)
    if ball is None:
        return Action(search=True)
    bx, by = ball
    ball_field = pose.to_field(bx, by)
    if math.hypot(bx, by) < 0.6 and ball_field[0] > pose.x_m + 0.1:
        # clear only a ball on the field side of the goalie; circling a ball that is behind
        # it, next to its own goal, could push it in
        return _striker(pose, ball, field, searching_s)
    bearing = math.atan2(by, bx)
    if abs(bearing) > 0.25:
        return Action(walk=(0.0, 0.0, _clip(1.0 * bearing, 0.4)))
    return STAND


def _search(searching_s: float) -> Action:
    """Scan with the head first; then turn on the spot while scanning."""
    if searching_s < 4.0:
        return Action(search=True)
    return Action(walk=(0.0, 0.0, 0.5), search=True)


def _clip(value: float, high: float, *, low: float | None = None) -> float:
    return min(max(value, -high if low is None else low), high)


def _wrap(angle: float) -> float:
    return math.atan2(math.sin(angle), math.cos(angle))
