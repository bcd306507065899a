"""The adult-size robot under the stub: it rises from straight legs, walks and plays the ball."""

from __future__ import annotations

from contracts.gamecontroller import GameState
from contracts.geometry import Pose
from robot.stub import GameInfo, Role, StubController

from .motion_world import OneRobot

ADULT = "adult-default"


def test_rises_from_straight_legs_without_falling() -> None:
    """Placed with all joints at zero, it eases into the stance instead of bending its knees at
    the servos' full speed (which throws it over backwards)."""
    robot = OneRobot(x_m=-2.0, model=ADULT)
    controller = StubController(
        role=Role.STRIKER,
        start_pose=Pose(x_m=-2.0, y_m=0.0, yaw_rad=0.0),
        model=ADULT,
        field_class="adult",
    )
    game = GameInfo(phase=GameState.PLAYING)
    busy: set[str] = set()

    def tick() -> dict[str, float]:
        targets = controller.tick(robot.sensors(), game)
        busy.add(controller.busy)
        return targets

    assert robot.run(5.0, tick), "fell"
    assert "rise" in busy
    assert controller.stats.falls == 0
    assert robot.up > 0.9
