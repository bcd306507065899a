"""Decisions of the stub: the defender keeps its spot and plays only a ball that comes near."""

from __future__ import annotations

import math

from contracts.gamecontroller import GameState
from contracts.geometry import Pose
from robot.stub.behaviour import STAND, Field, GameInfo, Role, decide

FIELD = Field(half_length_m=4.5, foot_y_m=0.06, kick_x_m=0.165)
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
    """Over distance the striker (and READY's walk) goes at the gait's cruise speed: the kid's
    0.4 m/s, the adult's 0.3 m/s (what its gait was measured at)."""
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
    assert speeds == {"kid-default": 0.4, "adult-default": 0.3}
