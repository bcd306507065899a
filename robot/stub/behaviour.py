"""Decisions of the stub robot: what to do this tick, from the game state and its beliefs.

Pure functions of plain data (no I/O), so the same code runs in a match and in the bench.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from enum import StrEnum

from contracts import GameState, Pose


class Role(StrEnum):
    STRIKER = "striker"
    GOALIE = "goalie"
    DEFENDER = "defender"  # keeps its home spot in the own half; plays a ball that comes near
    IDLE = "idle"


@dataclass(frozen=True, slots=True, kw_only=True)
class GameInfo:
    phase: GameState
    penalised: bool = False
    our_kick_off: bool = True
    first_half: bool = True
    on_left: bool | None = None  # the team's TeamInfo comes first in RGme: it plays on the left
    # PLAYING: the last restart (kick-off, or a set play just taken) is protected this long ...
    ball_free_in_s: float = 0.0
    # ... and it was ours (None: the kick-off's, ``our_kick_off``)
    restart_ours: bool | None = None
    # a set play (goal kick, corner kick, throw-in, free kick, penalty kick) being prepared: ours
    # (True) or the opponents' (False); None when none is
    set_play_ours: bool | None = None
    # its sub-phase: 0 the ball placed, robots still; 1 robots position; 2 robots freeze (the
    # GameController's secondaryStateInfo[1]); the set play is taken when 2 ends
    set_play_phase: int = 0


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
APPROACH_M = 0.55  # nearer than this the striker lines up and kicks
BEHIND_M = 0.35  # where it heads for: this far behind the ball, on the goal line through it
BEHIND_KICK_M = 0.05  # ... and at least this much farther than its kick spot
ROUND_M = 0.5  # how wide it goes round a ball it is in front of
FAST_M_S = 0.3  # walking over distance, unless the model's gait says otherwise (Field.fast_m_s)
AIM_HALF_WIDTH_M = 0.8  # aim this close to the goal centre (posts at 1.3 m)
# At its own kick-off the striker plays the ball diagonally forward, past the opponents' kick-off
# spot in front of the centre circle (a ball kicked straight at the goal hits the opponent who
# stands there), towards this point (fractions of the half length: 3 m, 1 m on the kid field)
KICK_OFF_AIM = (0.67, 0.22)
KICK_OFF_AIM_TOLERANCE_RAD = 0.12
KICK_OFF_PLACE_M = 0.06  # READY: the kick-off striker's place against the ball, this close
KICK_OFF_YAW_RAD = 0.08  # ... and its heading this close to the kick-off pass
KICK_OFF_SHORT_M = 0.04  # READY: the ball this much farther than the kick spot (no touching)
KICK_OFF_ARRIVE_RAD = 1.2  # READY: the kick-off striker comes to its place within this of behind
KICK_OFF_ROUND_BACK = 0.8  # ... else by a point this many centre-circle radii behind its place
CENTRE_SPOT_M = 0.3  # a ball this close to the centre spot is a kick-off ball
# READY at the opponents' kick-off: outside the centre circle by this fraction of its radius
# (0.25 m kid, 0.5 m adult: the adult's believed position was off by up to 0.5 m there after a
# match's walking, and 0.25 m left it inside the circle at SET)
OUTSIDE_CIRCLE_FRACTION = 1.0 / 3.0
HALFWAY_MARGIN_M = 0.5  # ... and, beside the circle, this far behind the halfway line
SET_PLAY_MARGIN_M = 0.2  # at the opponents' set play: backs off when nearer than the distance
# and this, to the distance and twice this
SEARCH_TURN_AFTER_S = 2.0
DEFENDER_HOME = (-2.3, 0.0)  # when none is given
DEFENDER_ENGAGE_M = 1.2  # a defender plays a ball this close to its home spot
DEFENDER_NEAR_M = 0.8  # ... or this close to itself


@dataclass(frozen=True, slots=True, kw_only=True)
class Field:
    half_length_m: float
    centre_circle_m: float  # radius of the centre circle (0.75 m kid, 1.5 m adult)
    foot_y_m: float  # lateral distance of each foot from the centre line
    kick_x_m: float  # best ball distance in front of the pelvis for a kick
    kick_feet: tuple[str, ...] = ("left", "right")  # the feet it kicks with
    fast_m_s: float = FAST_M_S  # forward speed over distance (the gait's cruise speed)
    opponent_distance_m: float = 0.75  # keep this far from the ball at the opponents' set plays


def decide(
    *,
    role: Role,
    game: GameInfo,
    pose: Pose,
    ball: tuple[float, float] | None,
    field: Field,
    searching_s: float,
    home: tuple[float, float] | None = None,
) -> Action:
    """``ball`` is relative to the robot (x forward, y left) or None when not seen lately;
    ``searching_s`` how long the ball has been missing; ``home`` a defender's spot (own-half
    frame)."""
    if role is Role.IDLE or game.penalised or game.phase in (GameState.INITIAL, GameState.SET):
        return STAND
    if game.phase is GameState.FINISHED:
        return STAND
    if game.phase is GameState.READY:
        target = _kick_off_position(role, game, field, home, pose)
        kicks_off = role is Role.STRIKER and game.our_kick_off
        ball_field = _kick_off_ball(pose, ball) if kicks_off else None
        if ball_field is not None:
            # The ball on the centre spot is a landmark: place against it, not against the
            # odometry (a few centimetres off after the walk), so that the kick-off comes at
            # once in PLAYING instead of after seconds of lining up.
            target = Pose(x_m=target.x_m + ball_field[0], y_m=target.y_m + ball_field[1],
                          yaw_rad=target.yaw_rad)
        if kicks_off:
            way = _kick_off_way(pose, target, field)
            if way is not target:
                return _go_to(pose, way, fast_m_s=field.fast_m_s)
        if ball_field is not None:
            return _go_to(pose, target, fast_m_s=field.fast_m_s,
                          tolerance_m=KICK_OFF_PLACE_M, yaw_tolerance_rad=KICK_OFF_YAW_RAD)
        return _go_to(pose, target, fast_m_s=field.fast_m_s)
    # PLAYING
    if game.set_play_ours is not None:
        return _set_play(role, game, pose, ball, field, searching_s)
    restart_ours = game.our_kick_off if game.restart_ours is None else game.restart_ours
    if not restart_ours and game.ball_free_in_s > 0:
        return STAND  # the opponents' kick-off or set play: keep away until the ball is free
    if role is Role.GOALIE:
        return _goalie(pose, ball, field, searching_s)
    if role is Role.DEFENDER:
        return _defender(pose, ball, field, searching_s, home or DEFENDER_HOME)
    if game.our_kick_off and _kick_off_ball(pose, ball) is not None:
        return _striker(pose, ball, field, searching_s, aim=_kick_off_aim(field))
    return _striker(pose, ball, field, searching_s)


def _set_play(
    role: Role,
    game: GameInfo,
    pose: Pose,
    ball: tuple[float, float] | None,
    field: Field,
    searching_s: float,
) -> Action:
    """While a set play is prepared: at the opponents', keep the set-play distance from the ball
    (backing off towards the own goal when nearer) and wait; at ours, stand while the robots
    must (sub-phases 0 and 2) and let the striker walk up behind the ball in sub-phase 1, to
    within about 0.75 m of it: the league's referee aborts a set play whose team touches the
    ball before it is taken (and warns the robot), so it lines up only then."""
    if not game.set_play_ours:
        if role is Role.GOALIE or ball is None:
            return _face(ball, tolerance_rad=0.4)
        if math.hypot(*ball) >= field.opponent_distance_m + SET_PLAY_MARGIN_M:
            return _face(ball, tolerance_rad=0.4)
        ball_field = pose.to_field(*ball)
        # the spot on the way from the ball to the own goal, just beyond the distance
        gx, gy = -field.half_length_m - ball_field[0], -ball_field[1]
        away = math.hypot(gx, gy) or 1.0
        keep = field.opponent_distance_m + 2.0 * SET_PLAY_MARGIN_M
        spot = (ball_field[0] + keep * gx / away, ball_field[1] + keep * gy / away)
        facing = math.atan2(ball_field[1] - spot[1], ball_field[0] - spot[0])
        return _go_to(pose, Pose(x_m=spot[0], y_m=spot[1], yaw_rad=facing),
                      fast_m_s=field.fast_m_s, tolerance_m=SET_PLAY_MARGIN_M)  # fmt: skip
    if role is not Role.STRIKER or game.set_play_phase != 1:
        return _face(ball, tolerance_rad=0.4) if game.set_play_phase == 1 else STAND
    if ball is not None and math.hypot(*ball) < APPROACH_M + SET_PLAY_MARGIN_M:
        # near enough to line up once it is taken: touching the ball now would abort it
        return STAND
    return _striker(pose, ball, field, searching_s)


def _kick_off_way(pose: Pose, target: Pose, field: Field) -> Pose:
    """READY, the kick-off striker: its place (``target``), when it comes to it from behind
    (within :data:`KICK_OFF_ARRIVE_RAD` of straight behind, along the kick-off pass); else a
    point :data:`KICK_OFF_ROUND_BACK` centre-circle radii behind its place, so that it does not
    walk past the ball and push it, as adult strikers coming from the side did (and followed it
    into the opponents' half, a penalty at SET)."""
    rx, ry = pose.x_m - target.x_m, pose.y_m - target.y_m
    distance = math.hypot(rx, ry)
    if distance < 2.0 * KICK_OFF_PLACE_M:
        return target
    dx, dy = math.cos(target.yaw_rad), math.sin(target.yaw_rad)
    if -(rx * dx + ry * dy) / distance >= math.cos(KICK_OFF_ARRIVE_RAD):
        return target
    back = KICK_OFF_ROUND_BACK * field.centre_circle_m
    return Pose(x_m=target.x_m - back * dx, y_m=target.y_m - back * dy, yaw_rad=target.yaw_rad)


def _kick_off_ball(pose: Pose, ball: tuple[float, float] | None) -> tuple[float, float] | None:
    """The ball's field position when it is seen on the centre spot (a kick-off ball), else
    None."""
    if ball is None:
        return None
    ball_field = pose.to_field(*ball)
    return ball_field if math.hypot(*ball_field) < CENTRE_SPOT_M else None


def _kick_off_aim(field: Field) -> tuple[float, float]:
    return KICK_OFF_AIM[0] * field.half_length_m, KICK_OFF_AIM[1] * field.half_length_m


def _kick_off_position(
    role: Role,
    game: GameInfo,
    field: Field,
    home: tuple[float, float] | None,
    pose: Pose | None = None,
) -> Pose:
    """Where to stand at the kick-off (``pose``: where the robot is now)."""
    if role is Role.GOALIE:
        return Pose(x_m=-field.half_length_m + 0.5, y_m=0.0, yaw_rad=0.0)
    if role is Role.DEFENDER:
        x, y = home or DEFENDER_HOME
        return Pose(x_m=x, y_m=y, yaw_rad=0.0)
    if not game.our_kick_off:  # the opponents' kick-off: just outside the centre circle
        outside = field.centre_circle_m * (1.0 + OUTSIDE_CIRCLE_FRACTION)
        if pose is not None and pose.x_m > -outside and abs(pose.y_m) < 2.0 * outside:
            # In front of the spot behind the circle, in the middle of the field (coming back
            # from the opponents' half after scoring): beside the circle, on the side it comes
            # from. The way to the spot behind it runs through the middle, into the kick-off
            # team's striker at the ball; adult strikers fell there or were still in the circle
            # at SET after half their goals.
            side = 1.0 if pose.y_m >= 0.0 else -1.0
            return Pose(x_m=-HALFWAY_MARGIN_M, y_m=side * outside, yaw_rad=0.0)
        return Pose(x_m=-outside, y_m=0.0, yaw_rad=0.0)
    # facing along the kick-off pass, the ball a little short of the kick spot of the left foot
    # (of the right one for a robot that kicks with it alone: a learned right-foot kick; from
    # the left foot's spot it side-stepped at the kick-off and struck the ball's right side)
    ax, ay = _kick_off_aim(field)
    direction = math.atan2(ay, ax)
    c, s = math.cos(direction), math.sin(direction)
    ahead = field.kick_x_m + KICK_OFF_SHORT_M
    left = field.foot_y_m if "left" in field.kick_feet else -field.foot_y_m
    return Pose(x_m=-(c * ahead - s * left), y_m=-(s * ahead + c * left), yaw_rad=direction)


def _defender(
    pose: Pose,
    ball: tuple[float, float] | None,
    field: Field,
    searching_s: float,
    home: tuple[float, float],
) -> Action:
    """Stay at home facing the ball, so that teammates do not crowd the striker; play the ball
    (as a striker) when it comes within reach of home or of the robot."""
    if ball is not None:
        bx, by = ball
        ball_field = pose.to_field(bx, by)
        near_home = math.hypot(ball_field[0] - home[0], ball_field[1] - home[1])
        if near_home < DEFENDER_ENGAGE_M or math.hypot(bx, by) < DEFENDER_NEAR_M:
            return _striker(pose, ball, field, searching_s)
    hx, hy = pose.to_relative(*home)
    if math.hypot(hx, hy) > 0.4:
        return _go_to(
            pose,
            Pose(x_m=home[0], y_m=home[1], yaw_rad=0.0),
            tolerance_m=0.3,
            fast_m_s=field.fast_m_s,
        )
    return _face(ball, tolerance_rad=0.3)


def _go_to(pose: Pose, target: Pose, *, fast_m_s: float, tolerance_m: float = 0.2,
           yaw_tolerance_rad: float = 0.2) -> Action:
    """Walk to ``target`` facing where it walks, then turn to the target's heading.

    Near the target (within twice the tolerance) it turns to the final heading and steps the
    last centimetres forwards, backwards and sideways: turning in place moves the robot a
    little, and walking back to the target's centre would undo the turn each time."""
    x, y = pose.to_relative(target.x_m, target.y_m)
    distance = math.hypot(x, y)
    error = _wrap(target.yaw_rad - pose.yaw_rad)
    if distance < tolerance_m:
        if abs(error) < yaw_tolerance_rad:
            return STAND
        return Action(walk=(0.0, 0.0, _clip(1.2 * error, 0.5)))
    if distance < 2.0 * tolerance_m:
        return Action(walk=(_clip(0.6 * x, 0.12, low=-0.05), _clip(0.6 * y, 0.05),
                            _clip(1.2 * error, 0.5)))
    bearing = math.atan2(y, x)
    # full speed while far, slowing down over the last metre to stop on the target
    forward = min(fast_m_s, max(0.12, 0.6 * distance)) if abs(bearing) < 0.35 else 0.0
    return Action(walk=(forward, 0.0, _clip(1.5 * bearing, 0.6)))


def _striker(
    pose: Pose,
    ball: tuple[float, float] | None,
    field: Field,
    searching_s: float,
    *,
    aim: tuple[float, float] | None = None,
) -> Action:
    """Play the ball towards ``aim`` (field frame; default the opponent goal's centre)."""
    if ball is None:
        return _search(searching_s)
    bx, by = ball
    distance = math.hypot(bx, by)
    bearing = math.atan2(by, bx)
    # direction from the ball to the opponent goal centre, relative to the robot's heading
    ball_field = pose.to_field(bx, by)
    aim_x, aim_y = aim if aim is not None else (field.half_length_m, 0.0)
    goal_dx, goal_dy = aim_x - ball_field[0], aim_y - ball_field[1]
    heading_error = _wrap(math.atan2(goal_dy, goal_dx) - pose.yaw_rad)
    ux, uy = math.cos(heading_error), math.sin(heading_error)
    behind = -(bx * ux + by * uy) < -0.1  # the robot is on the far side of the ball from goal
    if distance > APPROACH_M or not behind or abs(bearing) > 1.2:
        return _approach(bx, by, heading_error, field)
    if abs(heading_error) > 0.35:
        # circle around the ball: side-step while turning, keep about 0.3 m away
        return Action(
            walk=(
                _clip(0.8 * (distance - 0.3), 0.06),
                _clip(-0.2 * math.copysign(1.0, heading_error), 0.07),
                _clip(0.8 * heading_error + 0.8 * bearing, 0.7),
            )
        )
    # the farther the goal, the straighter the kick must be to land between the posts
    aim_tolerance = min(max(math.atan2(AIM_HALF_WIDTH_M, math.hypot(goal_dx, goal_dy)), 0.12), 0.3)
    if aim is not None:
        aim_tolerance = KICK_OFF_AIM_TOLERANCE_RAD
    foot = "left" if by > 0 else "right"
    if foot not in field.kick_feet:
        foot = field.kick_feet[0]
    target_y = field.foot_y_m if foot == "left" else -field.foot_y_m
    ex, ey = bx - field.kick_x_m, by - target_y
    if abs(ex) < 0.05 and abs(ey) < 0.035 and abs(heading_error) < aim_tolerance:
        return Action(kick_foot=foot)
    return Action(
        walk=(
            _clip(0.8 * ex, 0.08, low=-0.05),
            _clip(1.2 * ey, 0.05),
            _clip(0.8 * heading_error, 0.3),
        )
    )


def _approach(bx: float, by: float, goal_bearing: float, field: Field) -> Action:
    """Walk to a point behind the ball on the line from the goal centre through the ball (the
    robot frame; ``goal_bearing`` the direction from the ball to the goal), a little farther
    than the kick spot (it steps back only slowly). When the robot is
    on the goal side of the ball, go round it first, on the side it is already on, so that it
    neither pushes the ball towards its own goal nor has to circle it for long."""
    ux, uy = math.cos(goal_bearing), math.sin(goal_bearing)
    along = -(bx * ux + by * uy)  # the robot relative to the ball, along ball -> goal
    if along > -0.1:
        beside = -(-bx * uy + by * ux)  # the robot relative to the ball, across the line
        side = 1.0 if beside >= 0 else -1.0
        px = bx - 0.25 * ux - side * ROUND_M * uy
        py = by - 0.25 * uy + side * ROUND_M * ux
    else:
        behind = max(BEHIND_M, field.kick_x_m + BEHIND_KICK_M)
        px, py = bx - behind * ux, by - behind * uy
    target = math.atan2(py, px)
    forward = field.fast_m_s if abs(target) < 0.3 else (0.06 if abs(target) < 0.7 else 0.0)
    return Action(walk=(forward, 0.0, _clip(1.5 * target, 0.7)))


def _goalie(
    pose: Pose, ball: tuple[float, float] | None, field: Field, searching_s: float
) -> Action:
    home = Pose(x_m=-field.half_length_m + 0.5, y_m=0.0, yaw_rad=0.0)
    hx, hy = pose.to_relative(home.x_m, home.y_m)
    if math.hypot(hx, hy) > 0.5:
        return _go_to(pose, home, tolerance_m=0.3, fast_m_s=field.fast_m_s)
    if ball is not None:
        bx, by = ball
        ball_field = pose.to_field(bx, by)
        if math.hypot(bx, by) < 0.6 and ball_field[0] > pose.x_m + 0.1:
            # clear only a ball on the field side of the goalie; circling a ball that is behind
            # it, next to its own goal, could push it in
            return _striker(pose, ball, field, searching_s)
    return _face(ball, tolerance_rad=0.25)


def _face(ball: tuple[float, float] | None, *, tolerance_rad: float) -> Action:
    """Stay on the spot turned towards the ball; scan for it when it is not seen."""
    if ball is None:
        return Action(search=True)
    bearing = math.atan2(ball[1], ball[0])
    if abs(bearing) > tolerance_rad:
        return Action(walk=(0.0, 0.0, _clip(1.0 * bearing, 0.4)))
    return STAND


def _search(searching_s: float) -> Action:
    """Scan with the head first; then turn on the spot while scanning."""
    if searching_s < SEARCH_TURN_AFTER_S:
        return Action(search=True)
    return Action(walk=(0.0, 0.0, 0.7), search=True)


def _clip(value: float, high: float, *, low: float | None = None) -> float:
    return min(max(value, -high if low is None else low), high)


def _wrap(angle: float) -> float:
    return math.atan2(math.sin(angle), math.cos(angle))
