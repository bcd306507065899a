"""The kick on the real MuJoCo robot moves the ball more than a metre and the robot stays up."""

from __future__ import annotations

import math

import pytest

from robot.motion import KickMotion, standing_posture

from .motion_world import OneRobot


@pytest.mark.parametrize("foot", ["right", "left"])
def test_kick_moves_the_ball_at_least_1_m(foot: str) -> None:
    robot = OneRobot()
    robot.stand()
    sole = robot.sole("R" if foot == "right" else "L")
    robot.place_ball(sole[0] + 0.14, sole[1])
    robot.stand(0.1)
    before = robot.ball_position
    kick = KickMotion(foot=foot)
    assert robot.run(kick.duration_s, lambda: kick.step(0.008)), "fell while kicking"
    assert robot.run(3.0, standing_posture)
    moved = robot.ball_position - before
    assert math.hypot(moved[0], moved[1]) >= 1.0
    assert moved[0] > 0.8 * math.hypot(moved[0], moved[1])  # forwards


def test_kick_rejects_an_unknown_foot() -> None:
    with pytest.raises(ValueError, match="foot"):
        KickMotion(foot="middle")
