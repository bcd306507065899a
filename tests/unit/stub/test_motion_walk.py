"""The walk engine on the real MuJoCo robot: forward, turning, sideways, no fall."""

from __future__ import annotations

import math

import pytest

from robot.motion import WalkEngine
from robot.motion.ik import FootTarget, leg_fk, leg_ik
from robot.motion.models import kinematics

from .motion_world import OneRobot


def walker(robot: OneRobot, engine: WalkEngine, vx: float, vy: float, vyaw: float):  # type: ignore[no-untyped-def]
    return lambda: engine.step(0.008, vx, vy, vyaw, accel=robot.accel, gyro=robot.gyro)


def test_leg_ik_round_trip() -> None:
    leg = kinematics("kid-default").leg
    for target in (FootTarget(0.03, 0.02, -0.3, 0.2), FootTarget(-0.05, -0.03, -0.28, -0.3)):
        back = leg_fk(leg, leg_ik(leg, target))
        assert back.x_m == pytest.approx(target.x_m, abs=1e-6)
        assert back.y_m == pytest.approx(target.y_m, abs=1e-6)
        assert back.z_m == pytest.approx(target.z_m, abs=1e-6)


def test_walks_forward_for_10_s_without_falling() -> None:
    robot = OneRobot()
    robot.stand()
    start = robot.position
    engine = WalkEngine(model="kid-default")
    assert robot.run(10.0, walker(robot, engine, 0.15, 0.0, 0.0)), "fell while walking"
    moved = robot.position - start
    assert moved[0] >= 1.0  # >= 0.1 m/s
    assert abs(moved[1]) < 0.5 * moved[0]


def test_walks_at_its_cruise_speed_and_turning_without_falling() -> None:
    """The speed a striker crosses the pitch at (the gait's cruise speed, 0.4 m/s commanded):
    at least 0.25 m/s straight ahead on the soft grass, and it stays up while turning at it."""
    from robot.motion.walk import default_walk_params

    cruise = default_walk_params("kid-default").cruise_vx_m_s
    assert cruise == pytest.approx(0.4)
    robot = OneRobot(x_m=-3.5)
    robot.stand()
    start = robot.position
    engine = WalkEngine(model="kid-default")
    assert robot.run(10.0, walker(robot, engine, cruise, 0.0, 0.0)), "fell at cruise speed"
    moved = robot.position - start
    assert moved[0] >= 2.5, moved  # >= 0.25 m/s including the start from standing
    assert robot.run(6.0, walker(robot, engine, cruise, 0.0, 0.3)), "fell turning at cruise speed"


def test_turns_on_the_spot() -> None:
    robot = OneRobot()
    robot.stand()
    engine = WalkEngine(model="kid-default")
    turned = 0.0
    previous = robot.yaw

    def step() -> dict[str, float]:
        nonlocal turned, previous
        turned += math.remainder(robot.yaw - previous, 2 * math.pi)
        previous = robot.yaw
        return engine.step(0.008, 0.0, 0.0, 0.5, accel=robot.accel, gyro=robot.gyro)

    assert robot.run(8.0, step)
    assert turned >= 2.5  # about 0.5 rad/s


def test_walks_sideways_a_little() -> None:
    robot = OneRobot()
    robot.stand()
    start = robot.position
    engine = WalkEngine(model="kid-default")
    assert robot.run(10.0, walker(robot, engine, 0.0, 0.05, 0.0))
    assert robot.position[1] - start[1] >= 0.2


@pytest.mark.slow
def test_walks_60_s_on_flat_ground_without_falling() -> None:
    robot = OneRobot(x_m=-3.0)
    robot.stand()
    engine = WalkEngine(model="kid-default")
    commands = [(0.15, 0.0, 0.0), (0.05, 0.0, 0.5), (0.0, 0.05, 0.0), (0.1, 0.0, -0.3)]
    for vx, vy, vyaw in commands:
        assert robot.run(15.0, walker(robot, engine, vx, vy, vyaw)), (vx, vy, vyaw)


def test_attitude_filter_ignores_an_all_zero_first_reading() -> None:
    from robot.motion import AttitudeFilter

    f = AttitudeFilter()
    f.update(0.008, (0.0, 0.0, 0.0), (0.0, 0.0, 0.0))
    att = f.update(0.008, (0.0, 0.0, 9.81), (0.0, 0.0, 0.0))
    assert abs(att.roll_rad) < 1e-6 and abs(att.pitch_rad) < 1e-6
    leaning = f.update(0.008, (-9.81 * math.sin(0.3), 0.0, 9.81 * math.cos(0.3)), (0.0, 0.3, 0.0))
    assert leaning.pitch_rad > 0  # leaning forward, both from the gyro and the accelerometer
