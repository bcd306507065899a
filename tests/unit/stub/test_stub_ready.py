"""In READY the stub walks from the touch line to its kick-off position by odometry alone."""

from __future__ import annotations

import math

import pytest

from contracts.gamecontroller import GameState
from contracts.geometry import Pose
from robot.stub import GameInfo, Role, StubController

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
