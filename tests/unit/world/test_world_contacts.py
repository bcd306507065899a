"""Contacts in the snapshot: robot against robot, hull points, and the package surface."""

from __future__ import annotations

import math

import pytest

import simulator.world
from contracts.ids import RobotId, TeamColor
from simulator.world import RobotPlacement, World
from tests.unit.world.conftest import RED_1, run_steps

BLUE_1 = RobotId(TeamColor.BLUE, 1)


def test_robots_pushed_together_report_each_other() -> None:
    world = World.create(
        field_class="kid",
        robots=[
            RobotPlacement(id=RED_1, model="kid-default", x_m=-1.0, y_m=2.0, yaw_rad=0.0),
            RobotPlacement(id=BLUE_1, model="kid-default", x_m=-0.75, y_m=2.0, yaw_rad=math.pi),
        ],
        seed=1,
    )
    snap = world.snapshot()
    assert snap.robot(RED_1).robot_contacts == frozenset()
    torso = world.model.body("red_1/torso").id
    seen: set[RobotId] = set()
    world.data.xfrc_applied[torso, 0] = 30.0
    for _ in range(60):
        world.step()
        seen |= world.snapshot().robot(RED_1).robot_contacts
        if seen:
            break
    assert seen == {BLUE_1}
    assert RED_1 in world.snapshot().robot(BLUE_1).robot_contacts


def test_hull_points_are_hands_and_feet(one_robot_world: World) -> None:
    run_steps(one_robot_world, 5)
    robot = one_robot_world.snapshot().robots[0]
    assert len(robot.hull_points) == 4
    x, y = robot.position[:2]
    for px, py in robot.hull_points:
        assert math.hypot(px - x, py - y) < 0.2
    left_hand, right_hand = robot.hull_points[0], robot.hull_points[1]
    # robot yawed 0.3 rad: the left hand is on its left
    side = -math.sin(0.3) * (left_hand[0] - right_hand[0]) + math.cos(0.3) * (
        left_hand[1] - right_hand[1]
    )
    assert side == pytest.approx(0.23, abs=0.01)


def test_world_surface_is_sorted_and_resolves() -> None:
    names = list(simulator.world.__all__)
    assert names == sorted(names, key=str.casefold)
    for name in names:
        assert hasattr(simulator.world, name)
