"""Decisions of the stub: the defender keeps its spot and plays only a ball that comes near."""

from __future__ import annotations

import math

import pytest

from contracts.gamecontroller import GameState
from contracts.geometry import Pose
from robot.stub.behaviour import STAND, Field, GameInfo, Role, decide

FIELD = Field(half_length_m=4.5, centre_circle_m=0.75, foot_y_m=0.06, kick_x_m=0.165)
PLAYING = GameInfo(phase=GameState.PLAYING)
HOME = (-2.3, 1.0)


def _defender(pose: Pose, ball_field: tuple[float, float] | None) -> object:
    ball = pose.to_relative(*ball_field) if ball_field is not None else None
    return decide(role=Role.DEFENDER, game=PLAYING, pose=pose, ball=ball, field=FIELD,
                  searching_s=0.0, home=HOME)  # fmt: skip


def test_defender_at_home_faces_a_far_ball_and_stays() -> None:
    at_home = Pose(x_m=HOME[0], y_m=HOME[1], yaw_rad=0.0)
    assert _defender(at_home, (2.0, 1.0)) == STAND  # straight ahead, far away
    turn = _defender(at_home, (2.0, 3.0))  # far, to the left
    assert turn.walk[0] == 0.0 and turn.walk[2] > 0.0  # type: ignore[attr-defined]


def test_defender_away_from_home_walks_back() -> None:
    away = Pose(x_m=-0.5, y_m=1.0, yaw_rad=math.pi)  # home is 1.8 m straight ahead
    action = _defender(away, (3.0, 0.0))
    assert action.walk[0] > 0.0  # type: ignore[attr-defined]


def test_defender_plays_a_ball_near_home_as_a_striker() -> None:
    at_home = Pose(x_m=HOME[0], y_m=HOME[1], yaw_rad=0.0)
    ball = (HOME[0] + 1.0, HOME[1])  # 1 m in front: within reach of home
    striker = decide(role=Role.STRIKER, game=PLAYING, pose=at_home,
                     ball=at_home.to_relative(*ball), field=FIELD, searching_s=0.0)  # fmt: skip
    assert _defender(at_home, ball) == striker != STAND


def test_defender_kick_off_position_is_its_home() -> None:
    ready = GameInfo(phase=GameState.READY)
    there = Pose(x_m=HOME[0], y_m=HOME[1], yaw_rad=0.0)
    assert decide(role=Role.DEFENDER, game=ready, pose=there, ball=None, field=FIELD,
                  searching_s=0.0, home=HOME) == STAND  # fmt: skip
    elsewhere = Pose(x_m=-1.0, y_m=1.0, yaw_rad=math.pi)  # home behind it... facing it
    action = decide(role=Role.DEFENDER, game=ready, pose=elsewhere, ball=None, field=FIELD,
                    searching_s=0.0, home=HOME)  # fmt: skip
    assert action.walk[0] > 0.0


def test_a_far_ball_is_walked_to_at_the_models_cruise_speed() -> None:
    """Over distance the striker (and READY's walk) goes at the gait's cruise speed: 0.4 m/s for
    both built-in models (what their gaits were measured at)."""
    from contracts.geometry import Pose as P
    from robot.stub.controller import StubController

    start = P(x_m=0.0, y_m=0.0, yaw_rad=0.0)
    speeds = {}
    for model, field_class in (("kid-default", "kid"), ("adult-default", "adult")):
        field = StubController(role=Role.STRIKER, start_pose=start, model=model,
                               field_class=field_class).field  # fmt: skip
        far = decide(role=Role.STRIKER, game=PLAYING, pose=start, ball=(3.0, 0.0), field=field,
                     searching_s=0.0)  # fmt: skip
        ready = decide(role=Role.STRIKER, game=GameInfo(phase=GameState.READY, our_kick_off=False),
                       pose=P(x_m=-4.0, y_m=0.0, yaw_rad=0.0), ball=None, field=field,
                       searching_s=0.0)  # fmt: skip
        assert far.walk[0] == ready.walk[0] == field.fast_m_s  # type: ignore[attr-defined]
        speeds[model] = field.fast_m_s
    assert speeds == {"kid-default": 0.4, "adult-default": 0.4}


def test_near_its_ready_spot_it_turns_to_the_final_heading_while_stepping_the_rest() -> None:
    """Just outside the spot's tolerance, behind it and facing the wrong way (a turn in place
    drifted it): it keeps turning to the spot's heading (the opponent goal) and steps the last
    centimetres, rather than turning back to face the spot's centre and undoing the turn."""
    ready = GameInfo(phase=GameState.READY, our_kick_off=False)
    spot = (-1.0, 0.0)  # facing the opponent goal (yaw 0)
    pose = Pose(x_m=spot[0], y_m=spot[1] - 0.25, yaw_rad=1.2)  # 0.25 m short, facing left
    action = decide(role=Role.STRIKER, game=ready, pose=pose, ball=None, field=FIELD,
                    searching_s=0.0)  # fmt: skip
    vx, vy, vyaw = action.walk  # type: ignore[attr-defined]
    assert vyaw < 0.0  # towards yaw 0, although the spot's centre is ahead and to the left
    assert vx > 0.0 and vy > 0.0  # the spot is ahead and to the left: stepped there
    far = Pose(x_m=spot[0], y_m=spot[1] - 1.5, yaw_rad=1.4)
    walk = decide(role=Role.STRIKER, game=ready, pose=far, ball=None, field=FIELD,
                  searching_s=0.0).walk  # type: ignore[attr-defined]  # fmt: skip
    assert walk[0] > 0.0 and walk[2] > 0.0  # far: walks to the spot, facing it


def test_the_kick_off_striker_places_itself_against_the_ball_it_sees() -> None:
    """READY of its own kick-off: the odometry puts the robot on its spot, but the ball (on the
    centre spot) is seen 10 cm further to the right than the odometry says: it steps right."""
    from robot.stub.behaviour import _kick_off_position

    ready = GameInfo(phase=GameState.READY, our_kick_off=True)
    spot = _kick_off_position(Role.STRIKER, ready, FIELD, None)
    ball_seen = spot.to_relative(0.0, -0.10)  # the ball 10 cm right of the centre spot
    assert decide(role=Role.STRIKER, game=ready, pose=spot, ball=spot.to_relative(0.0, 0.0),
                  field=FIELD, searching_s=0.0) == STAND  # fmt: skip
    action = decide(role=Role.STRIKER, game=ready, pose=spot, ball=ball_seen, field=FIELD,
                    searching_s=0.0)  # fmt: skip
    assert action.walk[1] < 0.0  # type: ignore[attr-defined]  # side-steps to the right



def test_at_the_opponents_kick_off_it_waits_outside_the_centre_circle_of_its_field() -> None:
    """READY of the opponents' kick-off: a third of the circle's radius outside the centre
    circle, 1.0 m from the centre spot on the kid field (radius 0.75 m), 2.0 m on the adult one
    (1.5 m), where the kid spot was a penalty for being inside the circle (and 1.75 m left the
    adult inside it at SET when its believed position was 0.5 m off)."""
    from robot.stub.behaviour import _kick_off_position
    from robot.stub.controller import StubController

    theirs = GameInfo(phase=GameState.READY, our_kick_off=False)
    spots = {}
    for model, field_class in (("kid-default", "kid"), ("adult-default", "adult")):
        field = StubController(role=Role.STRIKER, start_pose=Pose(x_m=0.0, y_m=0.0, yaw_rad=0.0),
                               model=model, field_class=field_class).field  # fmt: skip
        spot = _kick_off_position(Role.STRIKER, theirs, field, None)
        spots[field_class] = (spot.x_m, spot.y_m)
    assert spots["kid"] == pytest.approx((-1.0, 0.0))
    assert spots["adult"] == pytest.approx((-2.0, 0.0))


def _walk_to_kick(
    field: Field, start: Pose, ball_field: tuple[float, float]
) -> tuple[float, float]:
    """The striker's decisions with its walk commands followed exactly (steps of 50 ms) until it
    kicks: (seconds until the kick, metres stepped backwards)."""
    pose, backwards, t, dt = start, 0.0, 0.0, 0.05
    while t < 30.0:
        ball = pose.to_relative(*ball_field)
        action = decide(role=Role.STRIKER, game=PLAYING, pose=pose, ball=ball, field=field,
                        searching_s=0.0)  # fmt: skip
        if action.kick_foot is not None:
            return t, backwards
        vx, vy, vyaw = action.walk
        backwards += max(0.0, -vx) * dt
        c, s = math.cos(pose.yaw_rad), math.sin(pose.yaw_rad)
        pose = Pose(x_m=pose.x_m + (vx * c - vy * s) * dt, y_m=pose.y_m + (vx * s + vy * c) * dt,
                    yaw_rad=pose.yaw_rad + vyaw * dt)  # fmt: skip
        t += dt
    raise AssertionError(f"no kick from {start} in 30 s")


def test_a_striker_with_a_far_kick_spot_comes_in_behind_it() -> None:
    """The adult kicks a ball 0.41 m ahead of its pelvis, farther than the 0.35 m behind the ball
    the kid heads for: it heads for a point beyond its kick spot, so that it lines up walking
    forwards (it steps back only at 0.05 m/s). From three starts at an angle to the ball it
    kicks within 10 s, hardly stepping back (heading for 0.35 m: 9.2, 10.3 and 10.5 s)."""
    adult = Field(half_length_m=7.0, centre_circle_m=1.5, foot_y_m=0.17, kick_x_m=0.41,
                  fast_m_s=0.4)  # fmt: skip
    starts = (
        (Pose(x_m=-1.0, y_m=0.3, yaw_rad=0.0), (2.0, 0.0)),
        (Pose(x_m=0.0, y_m=-1.0, yaw_rad=0.8), (2.0, 0.5)),
        (Pose(x_m=3.0, y_m=1.0, yaw_rad=3.0), (2.0, 0.0)),  # in front of the ball: goes round
    )
    runs = [_walk_to_kick(adult, start, ball) for start, ball in starts]
    assert all(seconds < 10.0 for seconds, _ in runs), runs
    assert sum(backwards for _, backwards in runs) <= 0.05, runs


def test_back_from_the_opponents_half_it_goes_round_the_kick_off_team_at_the_ball() -> None:
    """READY of the opponents' kick-off after scoring: the spot behind the circle lies beyond
    the centre, where the kick-off striker stands at the ball (the adult scorers ran into it
    and fell, or were still in the circle at SET). Coming from the opponents' half it stands
    beside the circle on the side it comes from, in its own half, and its way there keeps
    clear of the kick-off striker's spot."""
    adult = Field(half_length_m=7.0, centre_circle_m=1.5, foot_y_m=0.17, kick_x_m=0.41,
                  fast_m_s=0.3)  # fmt: skip
    ready = GameInfo(phase=GameState.READY, our_kick_off=False)
    for start in (Pose(x_m=4.0, y_m=1.3, yaw_rad=0.0), Pose(x_m=6.0, y_m=-0.4, yaw_rad=0.3)):
        pose, t, dt, nearest = start, 0.0, 0.05, math.inf
        while t < 30.0:
            action = decide(role=Role.STRIKER, game=ready, pose=pose, ball=None, field=adult,
                            searching_s=0.0)  # fmt: skip
            vx, vy, vyaw = action.walk
            c, s = math.cos(pose.yaw_rad), math.sin(pose.yaw_rad)
            pose = Pose(x_m=pose.x_m + (vx * c - vy * s) * dt,
                        y_m=pose.y_m + (vx * s + vy * c) * dt,
                        yaw_rad=pose.yaw_rad + vyaw * dt)  # fmt: skip
            # the kick-off striker stands about 0.5 m behind the ball, in the other half
            nearest = min(nearest, math.hypot(pose.x_m - 0.5, pose.y_m))
            t += dt
        assert pose.x_m < -0.3, (start, pose)  # in its own half
        assert math.hypot(pose.x_m, pose.y_m) > 1.6, (start, pose)  # outside the circle
        assert math.copysign(1.0, pose.y_m) == math.copysign(1.0, start.y_m)
        assert nearest > 1.0, (start, nearest)
    # from its own half it still waits behind the circle
    spot = decide(role=Role.STRIKER, game=ready, pose=Pose(x_m=-3.0, y_m=-2.0, yaw_rad=0.0),
                  ball=None, field=adult, searching_s=0.0)  # fmt: skip
    assert spot.walk[0] >= 0.0


def _ready_walk(
    field: Field, start: Pose, place: Pose, seconds: float = 40.0
) -> tuple[Pose, float]:
    """The kick-off striker's READY decisions followed exactly, the ball seen on the centre
    spot: (where it ends, its pelvis' nearest approach to the ball while more than 0.3 m from
    its ``place``)."""
    ready = GameInfo(phase=GameState.READY, our_kick_off=True)
    pose, t, dt, nearest = start, 0.0, 0.05, math.inf
    while t < seconds:
        action = decide(role=Role.STRIKER, game=ready, pose=pose, ball=pose.to_relative(0.0, 0.0),
                        field=field, searching_s=0.0)  # fmt: skip
        vx, vy, vyaw = action.walk
        c, s = math.cos(pose.yaw_rad), math.sin(pose.yaw_rad)
        pose = Pose(x_m=pose.x_m + (vx * c - vy * s) * dt,
                    y_m=pose.y_m + (vx * s + vy * c) * dt,
                    yaw_rad=pose.yaw_rad + vyaw * dt)  # fmt: skip
        if math.hypot(pose.x_m - place.x_m, pose.y_m - place.y_m) > 0.3:
            nearest = min(nearest, math.hypot(pose.x_m, pose.y_m))
        t += dt
    return pose, nearest


def test_the_kick_off_striker_comes_to_the_ball_from_behind() -> None:
    """READY of its own kick-off: coming from beside the ball (after conceding), the straight
    way to its place runs past the ball, which the adult pushed 0.9 m into the opponents' half
    and followed (a penalty at SET); it goes round by a point behind its place. From its start
    on the touch line (behind-side) it walks straight in as before."""
    from robot.stub.behaviour import _kick_off_position

    adult = Field(half_length_m=7.0, centre_circle_m=1.5, foot_y_m=0.17, kick_x_m=0.41,
                  fast_m_s=0.3)  # fmt: skip
    ours = GameInfo(phase=GameState.READY, our_kick_off=True)
    place = _kick_off_position(Role.STRIKER, ours, adult, None)
    end, nearest = _ready_walk(adult, Pose(x_m=-0.7, y_m=2.15, yaw_rad=-1.6), place)
    assert math.hypot(end.x_m - place.x_m, end.y_m - place.y_m) < 0.15
    # the straight way passed the ball at 0.42 m (its feet reach 0.2 m, the ball's radius is
    # 0.11 m): a little odometry error and it pushed the ball; round the back, 0.6 m
    assert nearest > 0.55, nearest
    kid_place = _kick_off_position(Role.STRIKER, ours, FIELD, None)
    end, _ = _ready_walk(FIELD, Pose(x_m=-0.8, y_m=-3.1, yaw_rad=1.57), kid_place, seconds=20.0)
    assert math.hypot(end.x_m - kid_place.x_m, end.y_m - kid_place.y_m) < 0.1
