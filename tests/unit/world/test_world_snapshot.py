"""The world's snapshot equals one built the straightforward way, field by field, every step.

The reference below looks everything up by name in the model and walks the contact list in
Python; the world's builder (simulator/world/snapshot.py) gathers from precomputed indices,
reuses the contact classification between steps and builds the dataclasses through their
slots. The scene has robots pushed against each other, the ball rolling into a robot's feet, a
limp robot falling and a removed robot.
"""

from __future__ import annotations

import dataclasses
import math

import mujoco
import numpy as np
import pytest

from contracts.ids import RobotId, TeamColor
from referee.snapshot import (
    BallState,
    BodyPart,
    PlaceBall,
    RemoveRobot,
    RobotState,
    SetLimp,
    WorldSnapshot,
)
from simulator.world import RobotPlacement, World, robot_prefix
from simulator.world.frozen import slot_constructor
from simulator.world.snapshot import BallToucher

RED_1, RED_2 = RobotId(TeamColor.RED, 1), RobotId(TeamColor.RED, 2)
BLUE_1, BLUE_2, BLUE_3 = (RobotId(TeamColor.BLUE, n) for n in (1, 2, 3))
PARTS_BY_NAME = {part.value: part for part in BodyPart}
HULL_BODIES = ("hand_L", "hand_R", "foot_L", "foot_R")


def reference_sole(model: mujoco.MjModel, body: int) -> tuple[float, float, float, float]:
    """The foot's colliding boxes and spheres (unturned, as the built-in robots' are) as the
    rectangle they cover: x back, x front, y right, y left."""
    xs: list[float] = []
    ys: list[float] = []
    for geom in range(model.ngeom):
        if model.geom_bodyid[geom] != body:  # (all of them collide; a removed robot's don't)
            continue
        pos, size = model.geom_pos[geom], model.geom_size[geom]
        box, sphere = int(mujoco.mjtGeom.mjGEOM_BOX), int(mujoco.mjtGeom.mjGEOM_SPHERE)
        assert int(model.geom_type[geom]) in (box, sphere)
        hx, hy = (size[0], size[1]) if int(model.geom_type[geom]) == box else (size[0], size[0])
        xs += [pos[0] - hx, pos[0] + hx]
        ys += [pos[1] - hy, pos[1] + hy]
    return (float(min(xs)), float(max(xs)), float(min(ys)), float(max(ys)))


def reference_snapshot(world: World) -> WorldSnapshot:
    """Names looked up in the model, the contact list walked in Python, dataclass __init__."""
    model, data = world.model, world.data
    ball_joint = model.joint("ball/root")
    q, d = int(ball_joint.qposadr[0]), int(ball_joint.dofadr[0])
    ball = BallState(
        position=tuple(float(x) for x in data.qpos[q : q + 3]),  # type: ignore[arg-type]
        velocity=tuple(float(x) for x in data.qvel[d : d + 3]),  # type: ignore[arg-type]
    )
    if not world.robot_ids:
        return WorldSnapshot(sim_time_ms=world.sim_time_ms, ball=ball, robots=())
    prefixes = [robot_prefix(r) for r in world.robot_ids]
    torsos = [model.body(f"{p}/torso").id for p in prefixes]
    # the yaws of all robots in one call, as the simulator has always computed them
    yaws = np.arctan2(
        np.array([data.xmat[t][3] for t in torsos]), np.array([data.xmat[t][0] for t in torsos])
    ).tolist()
    ground: list[set[BodyPart]] = [set() for _ in prefixes]
    on_ball: list[set[BodyPart]] = [set() for _ in prefixes]
    touching: list[set[RobotId]] = [set() for _ in prefixes]

    def owner(geom: int) -> tuple[int, BodyPart] | None:
        name = model.geom(geom).name
        for number, prefix in enumerate(prefixes):
            if name.startswith(prefix + "/"):
                part = PARTS_BY_NAME.get(name[len(prefix) + 1 :].split(":", 1)[0])
                return (number, part) if part is not None else None
        return None

    for i in range(data.ncon):
        pair = [int(g) for g in data.contact.geom[i]]
        for mine, other in (pair, pair[::-1]):
            me = owner(mine)
            if me is None:
                continue
            number, part = me
            other_name = model.geom(other).name
            if other_name == "turf":
                ground[number].add(part)
            elif other_name == "ball:geom":
                on_ball[number].add(part)
            else:
                them = owner(other)
                if them is not None and them[0] != number:
                    touching[number].add(world.robot_ids[them[0]])
    robots = []
    for number, robot_id in enumerate(world.robot_ids):
        prefix, torso = prefixes[number], torsos[number]
        root = int(model.joint(f"{prefix}/root").qposadr[0])
        com_velocity = int(model.sensor(f"{prefix}/com_velocity").adr[0])
        hull = [data.xpos[model.body(f"{prefix}/{b}").id] for b in HULL_BODIES]
        robots.append(
            RobotState(
                id=robot_id,
                position=tuple(float(x) for x in data.qpos[root : root + 3]),  # type: ignore[arg-type]
                yaw_rad=yaws[number],
                center_of_mass=tuple(float(x) for x in data.subtree_com[torso]),  # type: ignore[arg-type]
                velocity=tuple(  # type: ignore[arg-type]
                    float(x) for x in data.sensordata[com_velocity : com_velocity + 3]
                ),
                ground_contacts=frozenset(ground[number]),
                ball_contacts=frozenset(on_ball[number]),
                robot_contacts=frozenset(touching[number]),
                hull_points=tuple((float(p[0]), float(p[1])) for p in hull),
                sole_outline=reference_sole(model, model.body(f"{prefix}/foot_L").id),
                fallen=any(p is not BodyPart.FOOT for p in ground[number])
                or float(data.xmat[torso][8]) < 0.5,
                limp=world.is_limp(robot_id),
                removed=world.is_removed(robot_id),
            )
        )
    return WorldSnapshot(
        sim_time_ms=world.sim_time_ms,
        ball=ball,
        robots=tuple(robots),
        last_ball_toucher=world.last_ball_toucher,
        last_ball_touch_ms=world.last_ball_touch_ms,
    )


def assert_same(snap: WorldSnapshot, ref: WorldSnapshot) -> None:
    assert type(snap) is WorldSnapshot and type(snap.ball) is BallState
    for robot, expected in zip(snap.robots, ref.robots, strict=True):
        assert type(robot) is RobotState
        for field in dataclasses.fields(RobotState):
            got, want = getattr(robot, field.name), getattr(expected, field.name)
            assert got == want, f"{robot.id} {field.name}: {got!r} != {want!r}"
            assert type(got) is type(want), f"{robot.id} {field.name}: {type(got)}"
    assert snap == ref
    assert hash(snap.robots) == hash(ref.robots)


def test_snapshot_equals_the_straightforward_one_every_step() -> None:
    world = World.create(
        field_class="kid",
        robots=[
            RobotPlacement(id=RED_1, model="kid-default", x_m=-1.0, y_m=2.0, yaw_rad=0.0),
            RobotPlacement(id=BLUE_1, model="kid-default", x_m=-0.75, y_m=2.0, yaw_rad=math.pi),
            RobotPlacement(id=RED_2, model="kid-default", x_m=-0.3, y_m=0.0, yaw_rad=0.0),
            RobotPlacement(id=BLUE_2, model="kid-default", x_m=1.5, y_m=-1.5, yaw_rad=math.pi),
            RobotPlacement(id=BLUE_3, model="kid-default", x_m=2.5, y_m=1.0, yaw_rad=math.pi),
        ],
        seed=5,
    )
    assert_same(world.snapshot(), reference_snapshot(world))
    world.apply(PlaceBall(position=(0.3, 0.0, world.field.ball_radius_m), velocity=(-1.5, 0, 0)))
    world.apply(SetLimp(robot=BLUE_2, limp=True))
    world.apply(RemoveRobot(robot=BLUE_3))
    world.data.xfrc_applied[world.model.body("red_1/torso").id, 0] = 30.0
    seen = {"robot contact": 0, "ball contact": 0, "fallen": 0, "off feet": 0, "toucher": 0}
    for _ in range(200):
        world.step()
        snap = world.snapshot()
        assert_same(snap, reference_snapshot(world))
        seen["robot contact"] += any(r.robot_contacts for r in snap.robots)
        seen["ball contact"] += any(r.ball_contacts for r in snap.robots)
        seen["fallen"] += any(r.fallen for r in snap.robots)
        seen["off feet"] += any(r.touches_ground_outside_feet for r in snap.robots)
        seen["toucher"] += snap.last_ball_toucher is not None
    assert all(seen.values()), seen  # every case the referee reads was compared
    final = world.snapshot()
    assert final.robot(BLUE_2).limp and final.robot(BLUE_3).removed
    assert not final.robot(RED_1).limp and not final.robot(RED_1).removed


def test_snapshot_without_robots() -> None:
    world = World.create(field_class="kid", robots=[], seed=1)
    world.step()
    assert_same(world.snapshot(), reference_snapshot(world))


def test_slot_constructor_builds_the_dataclass_itself() -> None:
    make = slot_constructor(BallState)
    ball = make(position=(1.0, 2.0, 3.0), velocity=(0.0, 0.5, 0.0))
    assert type(ball) is BallState
    assert ball == BallState(position=(1.0, 2.0, 3.0), velocity=(0.0, 0.5, 0.0))
    with pytest.raises(dataclasses.FrozenInstanceError):
        ball.position = (0.0, 0.0, 0.0)  # type: ignore[misc]
    positional = slot_constructor(BallState, positional=True)
    assert positional((1.0, 2.0, 3.0), (0.0, 0.5, 0.0)) == ball
    with pytest.raises(TypeError):
        make(position=(1.0, 2.0, 3.0))  # every field is required


def test_slot_constructor_refuses_what_it_cannot_copy() -> None:
    @dataclasses.dataclass
    class Mutable:
        x: int

    @dataclasses.dataclass(frozen=True)
    class NotSlotted:
        x: int

    @dataclasses.dataclass(frozen=True, slots=True)
    class Checked:
        x: int

        def __post_init__(self) -> None:
            if self.x < 0:
                raise ValueError("x")

    for cls in (Mutable, NotSlotted, Checked):
        with pytest.raises(TypeError, match=cls.__name__):
            slot_constructor(cls)


def test_ball_toucher_reads_the_lowest_robot_touching_the_ball() -> None:
    """The strided view of the robots' ball-touch sensors (made once) reads what a gather of
    their addresses reads, and sees later steps (MuJoCo never moves ``sensordata``)."""
    world = World.create(
        field_class="kid",
        robots=[RobotPlacement(id=RobotId(TeamColor.RED if i % 2 else TeamColor.BLUE, i // 2 + 1),
                               model="kid-default", x_m=-2.0 + i, y_m=1.0, yaw_rad=0.0)
                for i in range(5)],  # fmt: skip
        seed=1,
    )
    toucher = BallToucher(world.data, world.index)
    adr = world.index.ball_touch
    rng = np.random.default_rng(2)
    for _ in range(50):
        world.step()
        world.data.sensordata[adr] = rng.integers(0, 2, adr.size) * rng.integers(1, 4, adr.size)
        touching = np.flatnonzero(world.data.sensordata[adr])
        assert toucher() == (int(touching[0]) if touching.size else -1)
    world.data.sensordata[adr] = 0.0
    assert toucher() == -1
    empty = World.create(field_class="kid", robots=[], seed=1)
    assert BallToucher(empty.data, empty.index)() == -1


def test_contact_view_is_the_contact_list_through_a_reset() -> None:
    """The snapshot's view of the contacts' geom pairs (made once over the arena) reads what
    ``data.contact.geom`` reads, every step, also after ``mj_resetData`` and a reload."""
    import mujoco

    world = World.create(
        field_class="kid",
        robots=[RobotPlacement(id=RED_1, model="kid-default", x_m=0.0, y_m=0.0, yaw_rad=0.0)],
        seed=2,
    )
    builder = world._snapshots
    compared = 0
    for step in range(300):
        if step == 150:
            mujoco.mj_resetData(world.model, world.data)
            mujoco.mj_forward(world.model, world.data)
        world.step()
        world.snapshot()
        ncon = world.data.ncon
        if ncon:
            assert np.array_equal(builder._contact_geoms()[:ncon], world.data.contact.geom)
            compared += 1
    assert compared >= 250  # (after the reset the robot drops from its model pose: none)
    assert not builder._contact_geoms().flags.writeable
