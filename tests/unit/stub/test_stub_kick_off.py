"""The stub's kick-off: a diagonal pass past the opponents' kick-off spot, and the centre-spot ball
as a landmark for its position in READY and SET."""

from __future__ import annotations

import math

import pytest

from contracts.gamecontroller import GameState
from contracts.geometry import Pose
from robot.stub.behaviour import Action, Field, GameInfo, Role, decide
from robot.stub.world_model import WorldModel

FIELD = Field(half_length_m=4.5, centre_circle_m=0.75, foot_y_m=0.075, kick_x_m=0.165)


def _striker(game: GameInfo, pose: Pose, ball_field: tuple[float, float]) -> Action:
    return decide(role=Role.STRIKER, game=game, pose=pose, ball=pose.to_relative(*ball_field),
                  field=FIELD, searching_s=0.0)  # fmt: skip


def _lined_up(heading: float, ball_field: tuple[float, float]) -> Pose:
    """A pose with the ball in front of the right foot, facing ``heading``."""
    bx, by = ball_field
    c, s = math.cos(heading), math.sin(heading)
    # the ball at (kick_x, -foot_y) in the robot frame
    return Pose(x_m=bx - c * FIELD.kick_x_m - s * FIELD.foot_y_m,
                y_m=by - s * FIELD.kick_x_m + c * FIELD.foot_y_m, yaw_rad=heading)  # fmt: skip


def test_own_kick_off_is_played_diagonally_past_the_centre() -> None:
    playing = GameInfo(phase=GameState.PLAYING, our_kick_off=True)
    diagonal = math.atan2(0.22, 0.67)
    # lined up at the goal centre: not yet, it turns towards the diagonal
    straight = _striker(playing, _lined_up(0.0, (0.0, 0.0)), (0.0, 0.0))
    assert straight.kick_foot is None
    assert straight.walk[2] > 0.0
    # lined up on the diagonal: it kicks
    assert _striker(playing, _lined_up(diagonal, (0.0, 0.0)), (0.0, 0.0)).kick_foot == "right"
    # a ball away from the centre spot is shot at the goal centre as before
    ball = (2.0, 0.0)
    assert _striker(playing, _lined_up(0.0, ball), ball).kick_foot == "right"
    assert _striker(playing, _lined_up(diagonal, ball), ball).kick_foot is None


def test_opponents_kick_off_ball_is_shot_at_the_goal() -> None:
    theirs = GameInfo(phase=GameState.PLAYING, our_kick_off=False)
    assert _striker(theirs, _lined_up(0.0, (0.0, 0.0)), (0.0, 0.0)).kick_foot == "right"


def test_ready_spot_for_the_own_kick_off_faces_the_pass_with_the_ball_short_of_a_kick() -> None:
    ready = GameInfo(phase=GameState.READY, our_kick_off=True)
    diagonal = math.atan2(0.22, 0.67)
    # the ball 8 cm farther than the kick spot, in front of the left foot
    ahead, left = FIELD.kick_x_m + 0.08, FIELD.foot_y_m
    c, s = math.cos(diagonal), math.sin(diagonal)
    left_foot = Pose(x_m=-(c * ahead - s * left), y_m=-(s * ahead + c * left), yaw_rad=diagonal)
    assert _striker(ready, left_foot, (0.0, 0.0)).stands
    bx, by = left_foot.to_relative(0.0, 0.0)
    assert bx == pytest.approx(ahead) and by == pytest.approx(left)
    assert not _striker(ready, Pose(x_m=-0.35, y_m=0.0, yaw_rad=0.0), (0.0, 0.0)).stands


def test_centre_spot_ball_pulls_the_believed_position_towards_the_truth() -> None:
    truth = Pose(x_m=-1.0, y_m=-0.5, yaw_rad=0.3)
    world = WorldModel(Pose(x_m=-0.4, y_m=0.2, yaw_rad=0.3))  # odometry 0.9 m off
    seen = truth.to_relative(0.0, 0.0)  # the ball on the centre spot, as the camera sees it
    before = math.hypot(world.pose.x_m - truth.x_m, world.pose.y_m - truth.y_m)
    world.relocate_from_centre_ball(*seen, gain=0.5)
    after = math.hypot(world.pose.x_m - truth.x_m, world.pose.y_m - truth.y_m)
    assert after == pytest.approx(0.5 * before)
    assert world.pose.yaw_rad == 0.3  # the heading is the gyro's
    for _ in range(20):
        world.relocate_from_centre_ball(*seen, gain=0.5)
    assert world.pose.x_m == pytest.approx(truth.x_m, abs=1e-4)
    assert world.pose.y_m == pytest.approx(truth.y_m, abs=1e-4)
    assert world.ball_field == pytest.approx((0.0, 0.0), abs=1e-4)
