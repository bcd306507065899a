"""A penalised robot is held standing while removed (no collapse, no fall to count)."""

from __future__ import annotations

import pytest

from contracts.geometry import Pose
from referee.rules.removal import removal_commands, return_commands
from simulator.world import World

from .conftest import RED_1, run_steps


def test_removed_robot_is_held_standing_and_released_standing(one_robot_world: World) -> None:
    world = one_robot_world
    for name in world.motor_names(RED_1):  # whatever its team commanded before the penalty
        world.set_motor_position(RED_1, name, 0.4)
    run_steps(world, 50)
    for command in removal_commands(RED_1, Pose(x_m=-1.5, y_m=-3.0, yaw_rad=1.57)):
        world.apply(command)
    standing = world.snapshot().robot(RED_1).position[2]
    heights = []
    for _ in range(375):  # 3 s held out of play
        world.set_motor_position(RED_1, "LegLowerL", 2.0)  # its team's commands wait
        world.step()
        heights.append(world.snapshot().robot(RED_1).position[2])
    snap = world.snapshot().robot(RED_1)
    assert snap.limp and not snap.fallen
    assert min(heights) > standing - 0.02  # held in its standing pose, not folded up
    for command in return_commands(RED_1):
        world.apply(command)
    world.set_motor_position(RED_1, "LegLowerL", 0.0)
    run_steps(world, 125)
    snap = world.snapshot().robot(RED_1)
    assert not snap.limp and not snap.fallen
    assert snap.position[:2] == pytest.approx((-1.5, -3.0), abs=0.05)
