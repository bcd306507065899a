from __future__ import annotations

import math
import os

import pytest

from contracts.gamecontroller import GameState
from contracts.geometry import Pose
from robot.stub.behaviour import Field, GameInfo, Role, decide
from testkit.stub_world import run_shot, shot_layout

FIELD = Field(half_length_m=4.5, centre_circle_m=0.75, foot_y_m=0.075, kick_x_m=0.165)
PLAYING = GameInfo(phase=GameState.PLAYING)


def _striker(pose: Pose, ball: tuple[float, float]) -> tuple[float, float, float]:
    action = decide(
        role=Role.STRIKER, game=PLAYING, pose=pose, ball=ball, field=FIELD, searching_s=0.0
    )
    return action.walk


def test_goes_round_a_ball_it_stands_in_front_of() -> None:
    # robot at x=3 facing its own goal, ball 1 m ahead of it (nearer its own goal): walking
    # straight at the ball would push it the wrong way, so it heads off to one side
    vx, _, vyaw = _striker(Pose(x_m=3.0, y_m=0.2, yaw_rad=math.pi), (1.0, 0.0))
    assert abs(vyaw) > 0.3


def test_heads_for_the_point_behind_the_ball() -> None:
    # ball straight ahead, left of the field's centre line: the goal centre lies down-field to
    # the right of the ball, so the point behind the ball on that line is left of the ball
    _, _, vyaw = _striker(Pose(x_m=1.0, y_m=1.0, yaw_rad=0.0), (1.5, 0.0))
    assert vyaw > 0
    _, _, vyaw_other = _striker(Pose(x_m=1.0, y_m=-1.0, yaw_rad=0.0), (1.5, 0.0))
    assert vyaw_other < 0


def test_no_kick_while_aiming_beside_the_goal() -> None:
    ball = (FIELD.kick_x_m, -FIELD.foot_y_m)
    lined_up = decide(
        role=Role.STRIKER, game=PLAYING, pose=Pose(x_m=0.5, y_m=0.0, yaw_rad=0.0), ball=ball,
        field=FIELD, searching_s=0.0,
    )  # fmt: skip
    assert lined_up.kick_foot == "right"
    aiming_wide = decide(
        role=Role.STRIKER, game=PLAYING, pose=Pose(x_m=0.5, y_m=0.0, yaw_rad=0.25), ball=ball,
        field=FIELD, searching_s=0.0,
    )  # fmt: skip
    assert aiming_wide.kick_foot is None
    assert aiming_wide.walk[2] < 0  # turns towards the goal centre


def test_shot_layouts_lie_in_front_of_the_goal() -> None:
    for seed in range(50):
        (bx, by), (rx, ry, _) = shot_layout(seed)
        assert 1.5 - 1e-9 <= math.hypot(4.5 - bx, by) <= 4.0 + 1e-9
        assert abs(by) < 2.6 and abs(ry) < 2.7
        assert math.hypot(rx - bx, ry - by) == pytest.approx(1.0)


@pytest.mark.slow
def test_striker_scores_from_in_front_of_the_goal() -> None:
    os.environ.setdefault("MUJOCO_GL", "osmesa")
    os.environ.setdefault("PYOPENGL_PLATFORM", os.environ["MUJOCO_GL"])
    result = run_shot(seed=1004, time_limit_s=40.0, goalie=False)
    assert result.outcome == "goal", result
    assert result.kicks >= 1
