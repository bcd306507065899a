"""The stub finds out from its camera whether the pitch is mirrored for its team."""

from __future__ import annotations

import math

import pytest

from contracts.gamecontroller import GameState
from contracts.geometry import Pose
from robot.stub import GameInfo, Role, StubController
from simulator.world import CameraRenderer

from .motion_world import OneRobot


@pytest.mark.parametrize(("world_x", "mirrored"), [(-2.5, False), (2.5, True), (4.0, True)])
def test_side_check_from_the_own_goal(world_x: float, mirrored: bool) -> None:
    # as if playing on the left
    team_file_pose = Pose(x_m=-abs(world_x), y_m=-3.1, yaw_rad=math.pi / 2)
    robot = OneRobot(x_m=world_x, y_m=-3.1, yaw_rad=math.pi / 2)
    controller = StubController(role=Role.STRIKER, start_pose=team_file_pose, detect_side=True)
    game = GameInfo(phase=GameState.INITIAL)
    with CameraRenderer(robot.world, 320, 240) as camera:
        for _ in range(int(3.5 / 0.008)):
            robot.command(controller.tick(robot.sensors(camera), game))
            robot.world.step()
    assert controller.mirrored is mirrored
    pose = controller.world.pose
    expected_y = 3.1 if mirrored else -3.1
    assert pose.y_m == pytest.approx(expected_y, abs=0.05)
    assert math.copysign(1.0, pose.yaw_rad) == (-1.0 if mirrored else 1.0)


@pytest.mark.parametrize("on_left", [True, False])
def test_side_from_the_gamecontroller_team_order(on_left: bool) -> None:
    """RGme lists the team playing on the left first: the stub needs no look round then."""
    team_file_pose = Pose(x_m=-0.8, y_m=-3.1, yaw_rad=math.pi / 2)
    controller = StubController(role=Role.STRIKER, start_pose=team_file_pose, detect_side=True)
    robot = OneRobot(x_m=-0.8 if on_left else 0.8, y_m=-3.1, yaw_rad=math.pi / 2)
    game = GameInfo(phase=GameState.INITIAL, on_left=on_left)
    robot.command(controller.tick(robot.sensors(), game))
    assert controller.mirrored is (not on_left)
    pose = controller.world.pose
    assert pose.y_m == pytest.approx(-3.1 if on_left else 3.1)
    assert controller.busy == ""
