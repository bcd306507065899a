"""The stub's heading survives a fall: it follows the torso's whole orientation."""

from __future__ import annotations

import math

import numpy as np
import numpy.typing as npt
import pytest

from robot.stub.controller import HeadingTracker

G = 9.81


def _rotate(r: npt.NDArray[np.float64], omega: tuple[float, float, float], dt: float
            ) -> npt.NDArray[np.float64]:
    """Body -> world rotation after turning at body rates ``omega`` for ``dt``."""
    wx, wy, wz = omega
    skew = np.array([[0.0, -wz, wy], [wz, 0.0, -wx], [-wy, wx, 0.0]])
    turned: npt.NDArray[np.float64] = r @ (np.eye(3) + skew * dt)
    u, _, vt = np.linalg.svd(turned)
    rotation: npt.NDArray[np.float64] = u @ vt
    return rotation


def _track(motions: list[tuple[tuple[float, float, float], float]]) -> tuple[float, float]:
    """Feed a tracker the gyro and accelerometer of a robot turning through ``motions``
    (body rates, seconds); returns (heading change it reported, true heading change)."""
    tracker, r, dt = HeadingTracker(), np.eye(3), 0.008
    total = tracker.heading_change(dt, (0.0, 0.0, G), (0.0, 0.0, 0.0)) or 0.0
    for omega, seconds in motions:
        for _ in range(round(seconds / dt)):
            r = _rotate(r, omega, dt)
            up = r.T @ np.array([0.0, 0.0, 1.0])
            accel = (float(up[0] * G), float(up[1] * G), float(up[2] * G))
            total += tracker.heading_change(dt, accel, omega) or 0.0
    true = math.atan2(r[1, 0], r[0, 0])
    return total, true


def _wrap(angle: float) -> float:
    return math.atan2(math.sin(angle), math.cos(angle))


def test_turning_upright_is_the_gyro_yaw() -> None:
    reported, true = _track([((0.0, 0.0, 0.5), 2.0)])
    assert abs(_wrap(reported - 1.0)) < 0.01 and abs(_wrap(true - 1.0)) < 0.01


def test_falling_forward_turning_on_the_ground_and_getting_up() -> None:
    # over onto the front, a turn about the world vertical (the body's -x while face down),
    # back up: the robot stands turned by 0.8 rad although its gyro z never moved
    half_pi = math.pi / 2
    reported, true = _track([((0.0, half_pi, 0.0), 1.0), ((-0.8, 0.0, 0.0), 1.0),
                             ((0.0, -half_pi, 0.0), 1.0)])
    assert abs(_wrap(true - 0.8)) < 0.05
    assert abs(_wrap(reported - true)) < 0.05


def test_rolling_over_and_pitching_back_up_turns_the_heading_by_pi() -> None:
    # pitch over the top onto the back, then roll half a turn: upright, facing the other way
    reported, true = _track([((0.0, math.pi / 2, 0.0), 2.0), ((math.pi / 2, 0.0, 0.0), 2.0)])
    assert abs(_wrap(true - math.pi)) < 0.05
    assert abs(_wrap(reported - true)) < 0.05


def test_a_held_tracker_counts_no_turn_until_the_hold_is_over() -> None:
    """After a reset of the pose the referee may still be placing the robot: turns then are not
    the robot's."""
    tracker, dt = HeadingTracker(hold_s=0.5), 0.008
    placing = sum(
        tracker.heading_change(dt, (0.0, 0.0, G), (0.0, 0.0, 2.0)) or 0.0 for _ in range(50)
    )
    assert placing == 0.0  # 0.4 s of a 2 rad/s spin, all within the hold
    turned = sum(
        tracker.heading_change(dt, (0.0, 0.0, G), (0.0, 0.0, 1.0)) or 0.0 for _ in range(125)
    )
    assert turned == pytest.approx(1.0 * (125 - 13) * dt, abs=0.05)  # after the rest of the hold
