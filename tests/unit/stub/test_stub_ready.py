"""In READY the stub walks from the touch line to its kick-off position by odometry, and the
kick-off striker places itself against the ball it sees."""

from __future__ import annotations

import math

import pytest

from contracts.gamecontroller import GameState
from contracts.geometry import Pose
from contracts.timing import SCRIMMAGE
from robot.stub import GameInfo, Role, StubController
from robot.stub.behaviour import KICK_OFF_SHORT_M, _kick_off_aim
from simulator.world import CameraRenderer

from .motion_world import OneRobot


@pytest.mark.parametrize(
    ("role", "target"),
    [
        (Role.STRIKER, (-1.0, 0.0)),
        (Role.GOALIE, (-4.0, 0.0)),
        (Role.DEFENDER, (-2.3, -1.0)),
    ],
)
def test_walks_to_the_kick_off_position_in_ready(role: Role, target: tuple[float, float]) -> None:
    start = Pose(x_m=-1.5, y_m=-3.2, yaw_rad=math.pi / 2)  # on the touch line, facing the field
    robot = OneRobot(x_m=start.x_m, y_m=start.y_m, yaw_rad=start.yaw_rad)
    home = target if role is Role.DEFENDER else None
    controller = StubController(role=role, start_pose=start, home=home)
    game = GameInfo(phase=GameState.READY, our_kick_off=False)

    def tick() -> dict[str, float]:
        sensors = robot.sensors()
        return controller.tick(sensors, game)

    assert robot.run(45.0, tick), "fell on the way"
    x, y = robot.position[0], robot.position[1]
    assert math.hypot(x - target[0], y - target[1]) < 0.5
    assert abs(robot.yaw) < 0.4  # facing the opponent goal
    assert controller.last_action is not None and controller.last_action.stands


def test_the_kick_off_striker_stands_at_the_ball_before_a_short_ready_ends() -> None:
    """From the scrimmage's touch-line spot, in the scrimmage's 20 s READY: the striker of the
    kicking team walks to the ball on the centre spot and places itself against the ball it
    sees (not by odometry alone), facing the kick-off pass with the ball in front of its left
    foot, so that PLAYING starts with the kick rather than with seconds of lining up."""
    start = Pose(x_m=-0.8, y_m=-3.1, yaw_rad=math.pi / 2)
    robot = OneRobot(x_m=start.x_m, y_m=start.y_m, yaw_rad=start.yaw_rad)
    robot.place_ball(0.0, 0.0)
    controller = StubController(role=Role.STRIKER, start_pose=start)
    game = GameInfo(phase=GameState.READY, our_kick_off=True, on_left=True)
    field = controller.field
    with CameraRenderer(robot.world, 320, 240) as camera:
        assert robot.run(SCRIMMAGE.ready_duration_s,
                         lambda: controller.tick(robot.sensors(camera), game)), "fell"
    assert controller.last_action is not None and controller.last_action.stands
    ball = robot.ball_position
    assert math.hypot(ball[0], ball[1]) < 0.01  # not touched
    dx, dy = ball[0] - robot.position[0], ball[1] - robot.position[1]
    c, s = math.cos(robot.yaw), math.sin(robot.yaw)
    ahead, left = c * dx + s * dy, -s * dx + c * dy  # the ball in the robot's frame
    assert abs(ahead - (field.kick_x_m + KICK_OFF_SHORT_M)) < 0.05, (ahead, left)
    assert abs(left - field.foot_y_m) < 0.04, (ahead, left)
    aim_x, aim_y = _kick_off_aim(field)
    assert abs(math.remainder(robot.yaw - math.atan2(aim_y, aim_x), math.tau)) < 0.15


def test_the_goalie_walks_past_its_goal_to_its_spot_with_the_camera_on() -> None:
    """From the scrimmage's goalie spot on the touch line next to its goal, in the scrimmage's
    20 s READY: the goal's black and white net, which the camera can take for a ball, does not
    move its believed position (only a sighting near the centre spot corrects the odometry), so
    it stands in front of its goal, not metres behind it."""
    start = Pose(x_m=-4.0, y_m=-3.1, yaw_rad=math.pi / 2)
    robot = OneRobot(x_m=start.x_m, y_m=start.y_m, yaw_rad=start.yaw_rad)
    robot.place_ball(0.0, 0.0)
    controller = StubController(role=Role.GOALIE, start_pose=start)
    game = GameInfo(phase=GameState.READY, our_kick_off=False, on_left=True)
    with CameraRenderer(robot.world, 320, 240) as camera:
        assert robot.run(SCRIMMAGE.ready_duration_s,
                         lambda: controller.tick(robot.sensors(camera), game)), "fell"
    x, y = robot.position[0], robot.position[1]
    assert math.hypot(x - (-4.0), y) < 0.3, (x, y)
    assert abs(robot.yaw) < 0.3
