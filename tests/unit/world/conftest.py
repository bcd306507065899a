"""Helpers for the world tests: small worlds built in-process."""

from __future__ import annotations

import pytest

from contracts.ids import RobotId, TeamColor
from simulator.world import RobotPlacement, World

RED_1 = RobotId(TeamColor.RED, 1)


def eight_robots(model: str = "kid-default") -> list[RobotPlacement]:
    placements = []
    for team, sign in ((TeamColor.RED, -1.0), (TeamColor.BLUE, 1.0)):
        for n in range(1, 5):
            placements.append(
                RobotPlacement(
                    id=RobotId(team, n),
                    model=model,
                    x_m=sign * (0.8 + 0.8 * n),
                    y_m=-1.5 + (n - 1),
                    yaw_rad=0.0 if sign < 0 else 3.14159,
                )
            )
    return placements


@pytest.fixture
def one_robot_world() -> World:
    placement = RobotPlacement(id=RED_1, model="kid-default", x_m=-1.0, y_m=0.5, yaw_rad=0.3)
    return World.create(field_class="kid", robots=[placement], seed=7)


def run_steps(world: World, steps: int) -> None:
    for _ in range(steps):
        world.step()
