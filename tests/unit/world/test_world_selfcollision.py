"""Self-collision: a robot's non-adjacent links collide (simulator.world.selfcollision)."""

from __future__ import annotations

import pytest

from simulator.world import RobotPlacement, World
from simulator.world.robots import robot_model
from simulator.world.selfcollision import excluded_pairs

from .conftest import RED_1, run_steps

# An impossible kick: the weight over the right foot (hip and ankle rolls of 0.075 rad), then in
# one motion the left knee lifts and the left hip rolls to its inward limit, swinging the left leg
# across the stance leg. Passing through it, the swung leg's weight comes over the stance foot and
# the robot stands on one leg; striking it, the leg stays on the inside, pushes the stance leg out
# and the robot topples to its left (1.0 to 1.6 s later, for a weight shift from 0.065 to 0.085).
WEIGHT_RIGHT = {"PelvL": 0.075, "PelvR": 0.075, "FootL": -0.075, "FootR": -0.075}
KICK_ACROSS = {"LegUpperL": 0.6, "LegLowerL": 1.2, "AnkleL": 0.6, "PelvL": -0.6}

# a deep crouch with the hip rolls crossing the legs (each within its range): the knees meet and
# the legs wedge, holding the torso up; with the legs passing through each other it sinks lower.
# (On the rigid turf the wedge toppled the robot; on the soft grass it holds.)
CROSSED = {
    "LegUpperL": 0.6, "LegLowerL": 1.2, "AnkleL": 0.6,
    "LegUpperR": 0.6, "LegLowerR": 1.2, "AnkleR": 0.6,
    "PelvL": -0.6, "PelvR": 0.6,
}  # fmt: skip

# the left arm bent in and down against the torso's side (each joint within its range)
ARM_IN = {"ShoulderL": -0.7, "ArmUpperL": -0.3, "ArmLowerL": 1.4}

LEFT_LEG = {"thigh_L", "shank_L", "foot_L"}
RIGHT_LEG = {"thigh_R", "shank_R", "foot_R"}

Pairs = set[tuple[str, str]]
Place = tuple[float, float, float, int, float]

# where the robot stands (x, y, heading), and the seed and size of its initial joint noise
PLACES: list[Place] = [
    (0.0, 0.0, 0.0, 7, 0.0),
    (1.0, 0.0, 2.0, 4, 0.02),
    (-1.5, 1.2, -2.2, 23, 0.02),
]


def _world(*, self_collision: bool, place: Place = PLACES[0]) -> World:
    """One robot (the simulation is deterministic: the same command gives the same contacts and
    fall every run)."""
    x, y, yaw, seed, noise = place
    world = World.create(
        field_class="kid",
        robots=[RobotPlacement(id=RED_1, model="kid-default", x_m=x, y_m=y, yaw_rad=yaw)],
        seed=seed,
        initial_joint_noise_rad=noise,
    )
    if not self_collision:  # the robot's own bit masked: its links pass through each other
        world.model.geom_conaffinity[world.index.robots[0].geoms] &= ~1
    return world


def _own_contacts(world: World) -> Pairs:
    """The robot's contacts with itself, as pairs of link names."""
    model = world.model
    geoms = set(world.index.robots[0].geoms.tolist())
    link = [model.body(b).name.removeprefix("red_1/") for b in model.geom_bodyid]
    return {
        (link[a], link[b])
        for a, b in world.data.contact.geom[: world.data.ncon].tolist()
        if a in geoms and b in geoms
    }


def _command(world: World, targets: dict[str, float], steps: int) -> tuple[Pairs, bool]:
    """Set ``targets`` and step: the robot's own contacts meanwhile, and whether it fell."""
    for name, value in targets.items():
        world.set_motor_position(RED_1, name, value)
    seen: Pairs = set()
    fell = False
    for _ in range(steps):
        world.step()
        seen |= _own_contacts(world)
        fell = fell or world.snapshot().robot(RED_1).fallen
    return seen, fell


def _stiffen(world: World) -> None:
    """The gains the stub sets with MotorPID (P = 30), then settle."""
    for name in world.motor_names(RED_1):
        world.set_motor_pid(RED_1, name, 30.0, 0.0, 0.0)
    run_steps(world, 60)


def _leg_on_leg(seen: Pairs) -> bool:
    return any({a, b} & LEFT_LEG and {a, b} & RIGHT_LEG for a, b in seen)


def _kick_across(world: World) -> tuple[Pairs, bool]:
    """The impossible kick: the robot's own contacts, and whether it fell within 2 s."""
    _stiffen(world)
    seen, fell = _command(world, WEIGHT_RIGHT, 60)
    assert not fell  # standing, its weight over the right foot
    kicked, fell = _command(world, KICK_ACROSS, 250)
    return seen | kicked, fell


@pytest.mark.parametrize("place", PLACES)
def test_a_kick_across_the_stance_leg_strikes_it_and_the_robot_falls(place: Place) -> None:
    """Leg on leg: the swung leg meets the stance leg and the robot falls; the same command with
    the robot's own bit masked (the control: the leg passes through) leaves it standing."""
    seen, fell = _kick_across(_world(self_collision=True, place=place))
    assert _leg_on_leg(seen), seen
    assert fell
    passed, fell = _kick_across(_world(self_collision=False, place=place))
    assert not passed
    assert not fell


def _cross_legs(world: World) -> tuple[Pairs, float]:
    """The robot's own contacts while it crosses its legs, and its torso's height after."""
    _stiffen(world)
    seen, _ = _command(world, CROSSED, 400)
    return seen, world.snapshot().robot(RED_1).position[2]


def test_crossed_legs_wedge() -> None:
    """Leg on leg: the wedge holds the torso at least 2 cm above where the same command puts
    it with the robot's own bit masked."""
    seen, height = _cross_legs(_world(self_collision=True))
    assert _leg_on_leg(seen), seen
    passed, through = _cross_legs(_world(self_collision=False))
    assert not passed
    assert height > through + 0.02


def _hand_depth_in_torso(world: World) -> float:
    """How deep the left hand's centre is inside the torso's box (negative: outside it)."""
    model, data = world.model, world.data
    torso, hand = (model.geom(f"red_1/{name}").id for name in ("torso:torso", "hand:hand_L"))
    local = data.geom_xmat[torso].reshape(3, 3).T @ (data.geom_xpos[hand] - data.geom_xpos[torso])
    return float(min(model.geom_size[torso] - abs(local)))


def test_an_arm_bent_into_the_torso_meets_it() -> None:
    """Arm on torso: the forearm and hand stop at the torso's side; with the robot's own bit
    masked the hand's centre goes inside the torso."""
    world = _world(self_collision=True)
    _stiffen(world)
    seen, _ = _command(world, ARM_IN, 100)
    assert {("forearm_L", "torso"), ("hand_L", "torso")} <= {tuple(sorted(p)) for p in seen}, seen
    assert _hand_depth_in_torso(world) < -0.01  # held out (the hand's radius is 22 mm)
    world = _world(self_collision=False)
    _stiffen(world)
    passed, _ = _command(world, ARM_IN, 100)
    assert not passed
    assert _hand_depth_in_torso(world) > 0.0


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
