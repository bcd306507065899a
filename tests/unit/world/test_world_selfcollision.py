"""Self-collision: a robot's non-adjacent links collide (simulator.world.selfcollision)."""

from __future__ import annotations

from simulator.world import RobotPlacement, World
from simulator.world.robots import robot_model
from simulator.world.selfcollision import excluded_pairs

from .conftest import RED_1, run_steps

# a deep crouch with the hip rolls crossing the legs (each within its range): the knees meet and
# the legs wedge, holding the torso up; with the legs passing through each other it sinks lower.
# (On the rigid turf the wedge toppled the robot; on the soft grass it holds.)
CROSSED = {
    "LegUpperL": 0.6, "LegLowerL": 1.2, "AnkleL": 0.6,
    "LegUpperR": 0.6, "LegLowerR": 1.2, "AnkleR": 0.6,
    "PelvL": -0.6, "PelvR": 0.6,
}  # fmt: skip


def _own_contacts(world: World) -> set[tuple[str, str]]:
    names = [world.model.geom(g).name for g in range(world.model.ngeom)]
    return {
        (names[a], names[b])
        for a, b in world.data.contact.geom[: world.data.ncon].tolist()
        if names[a].startswith("red_1/") and names[b].startswith("red_1/")
    }


def _cross_legs(world: World) -> tuple[set[tuple[str, str]], float]:
    """The robot's own contacts while it crosses its legs, and its torso's height after."""
    for name in world.motor_names(RED_1):
        world.set_motor_pid(RED_1, name, 30.0, 0.0, 0.0)
    run_steps(world, 60)
    for name, value in CROSSED.items():
        world.set_motor_position(RED_1, name, value)
    seen: set[tuple[str, str]] = set()
    for _ in range(400):
        world.step()
        seen |= _own_contacts(world)
    return seen, world.snapshot().robot(RED_1).position[2]


def _world(*, self_collision: bool) -> World:
    """The robot at the centre spot facing +x (the simulation is deterministic: the same
    command gives the same wedge and fall every run)."""
    world = World.create(
        field_class="kid",
        robots=[RobotPlacement(id=RED_1, model="kid-default", x_m=0.0, y_m=0.0, yaw_rad=0.0)],
        seed=7,
    )
    if not self_collision:  # the robot's own bit masked: its links pass through each other
        world.model.geom_conaffinity[world.index.robots[0].geoms] &= ~1
    return world


def test_crossing_legs_collide_and_wedge() -> None:
    """Leg on leg: the wedge holds the torso at least 2 cm above where the same command puts
    it with the robot's own bit masked (the control: its legs pass through each other)."""
    seen, height = _cross_legs(_world(self_collision=True))
    assert any(a.endswith("_L") and b.endswith("_R") for a, b in seen), seen  # leg on leg
    passed, through = _cross_legs(_world(self_collision=False))
    assert not passed
    assert height > through + 0.02


def test_exclusion_rule_skips_links_without_collision_shapes() -> None:
    pairs = set(excluded_pairs(robot_model("kid-default")))
    # hip yaw and roll links carry no shapes: thigh and torso count as adjacent
    assert ("torso", "thigh_L") in pairs and ("torso", "upper_arm_R") in pairs
    assert ("shank_L", "foot_L") in pairs  # the ankle link between them has no shape
    assert not any("thigh_R" in pair and "thigh_L" in pair for pair in pairs)
    assert not any(pair == ("torso", "forearm_L") for pair in pairs)


def test_shapes_that_all_but_touch_in_the_reference_pose_count_as_touching() -> None:
    """The Wolfgang's head hull sits half a millimetre above its torso hull: without rule 2's
    margin, the head would stick on the torso as soon as it tilts down."""
    from pathlib import Path

    wolfgang = Path(__file__).resolve().parents[3] / "configs/examples/robots/wolfgang"
    pairs = set(excluded_pairs(robot_model(str(wolfgang))))
    assert ("torso", "link:head") in pairs
    assert ("torso", "link:l_upper_arm") not in pairs  # 15 mm apart: they collide
