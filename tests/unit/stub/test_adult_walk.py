"""The adult-size robot under the stub: it rises from straight legs, walks and plays the ball."""

from __future__ import annotations

import math
from collections.abc import Callable

from contracts.gamecontroller import GameState
from contracts.geometry import Pose
from robot.motion import KickMotion, WalkEngine, standing_posture
from robot.stub import GameInfo, Role, StubController

from .motion_world import OneRobot

ADULT = "adult-default"


def walker(
    robot: OneRobot, engine: WalkEngine, vx: float, vy: float, vyaw: float
) -> Callable[[], dict[str, float]]:
    return lambda: engine.step(0.008, vx, vy, vyaw, accel=robot.accel, gyro=robot.gyro)


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


def test_walks_forward_for_10_s_without_falling() -> None:
    """At the striker's full speed (0.3 m/s) it covered 2.76 m in 10 s, the ramp-up included."""
    robot = OneRobot(model=ADULT)
    robot.rise()
    start = robot.position
    engine = WalkEngine(model=ADULT)
    assert robot.run(10.0, walker(robot, engine, 0.3, 0.0, 0.0)), "fell while walking"
    moved = robot.position - start
    assert moved[0] >= 2.3
    assert abs(moved[1]) < 0.2 * moved[0]


def test_turns_while_walking_without_falling() -> None:
    """Walking at 0.3 m/s and turning at 0.4 rad/s, as the striker does on its way to the ball."""
    robot = OneRobot(model=ADULT)
    robot.rise()
    engine = WalkEngine(model=ADULT)
    start_yaw = robot.yaw
    assert robot.run(8.0, walker(robot, engine, 0.3, 0.0, 0.4)), "fell while turning"
    assert math.remainder(robot.yaw - start_yaw, 2 * math.pi) > 1.5


def test_kicks_without_falling() -> None:
    """The adult's kick from a stand sends the ball on and leaves the robot standing."""
    robot = OneRobot(x_m=-2.0, model=ADULT)
    robot.rise()
    robot.place_ball(-2.0 + 0.36, -0.14)
    kick = KickMotion(foot="right", model=ADULT, start=standing_posture(ADULT))
    assert robot.run(kick.duration_s + 1.5, lambda: kick.step(0.008)), "fell kicking"
    assert robot.ball_position[0] > -2.0 + 0.36 + 1.0
