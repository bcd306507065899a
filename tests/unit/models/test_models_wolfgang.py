"""The Wolfgang description, unchanged from its authors, as a team model: rules, world, camera."""

from __future__ import annotations

import io
import json
import math
from pathlib import Path

import jsonschema
import mujoco
import numpy as np

from contracts.ids import RobotId, TeamColor
from hlvs.commands.check import check_file, check_report
from referee.snapshot import BodyPart
from simulator.world import RobotPlacement, World
from simulator.world.camera import CameraRenderer
from simulator.world.robots.team import load_team_model
from simulator.world.robots.team.build import DROPPED
from simulator.world.robots.team.manifest import load_manifest
from simulator.world.robots.team.rulebook import check
from simulator.world.robots.team.source import load_spec
from simulator.world.types import DeviceKind
from tests.unit.models.conftest import WOLFGANG

RED_1 = RobotId(TeamColor.RED, 1)
BLUE_1 = RobotId(TeamColor.BLUE, 1)
SCHEMA = Path(__file__).resolve().parents[3] / "configs" / "schemas" / "robot_model.schema.json"


def _world() -> World:
    return World.create(
        field_class="kid",
        robots=[
            RobotPlacement(id=RED_1, model=str(WOLFGANG), x_m=-1.0, y_m=0.5, yaw_rad=0.0),
            RobotPlacement(id=BLUE_1, model="kid-default", x_m=1.0, y_m=0.0, yaw_rad=math.pi),
        ],
        seed=5,
    )


def test_manifest_follows_its_schema() -> None:
    schema = json.loads(SCHEMA.read_text())
    jsonschema.validate(json.loads((WOLFGANG / "robot_model.json").read_text()), schema)


def test_rule_book_measurements_of_a_kid_size_robot() -> None:
    measurements, problems = check(load_team_model(WOLFGANG))
    assert problems == []
    # Wolfgang is about 0.8 m tall and 6.1 kg (its URDF's link masses)
    assert 0.78 < measurements.height_m < 0.86
    assert 0.35 * measurements.height_m < measurements.leg_m < 0.7 * measurements.height_m
    assert abs(measurements.mass_kg - 6.117) < 0.01
    assert (measurements.motors, measurements.cameras) == (20, 1)
    out = io.StringIO()
    assert check_file(WOLFGANG, out=out) == 0
    report = check_report(WOLFGANG).as_json()
    assert report["valid"] is True and report["kind"] == "robot model"
    assert report["measurements"]["motors"] == 20
    assert "H 0.8" in out.getvalue() and out.getvalue().rstrip().endswith("ok (robot model)")


def test_devices_are_the_manifest_names() -> None:
    world = _world()
    devices = world.devices(RED_1)
    assert (
        devices["HeadPan"] is DeviceKind.MOTOR
        and devices["HeadTiltS"] is DeviceKind.POSITION_SENSOR
    )
    assert {devices[n] for n in ("llb", "rrf")} == {DeviceKind.FORCE}
    assert devices["Camera"] is DeviceKind.CAMERA and "Neck" not in devices
    assert len([k for k, v in devices.items() if v is DeviceKind.MOTOR]) == 20


def test_stands_in_its_standing_pose_then_falls_when_pushed() -> None:
    world = _world()
    start = world.snapshot().robots[0]
    for _ in range(375):  # 3 s
        world.step()
    standing = world.snapshot().robots[0]
    assert not standing.fallen and standing.ground_contacts == frozenset({BodyPart.FOOT})
    assert abs(standing.position[2] - start.position[2]) < 0.02
    assert math.dist(standing.position[:2], start.position[:2]) < 0.03
    pressure = sum(world.read_force(RED_1, n) for n in ("llb", "llf", "lrf", "lrb"))
    assert pressure > 5.0  # the left sole carries weight
    dof = world.index.robots[0].root_dof
    world.data.qvel[dof : dof + 3] = (1.5, 0.0, 0.0)
    for _ in range(375):
        world.step()
    pushed = world.snapshot().robots[0]
    assert pushed.fallen and pushed.ground_contacts - {BodyPart.FOOT}  # lying on the turf
    assert pushed.position[2] < 0.25
    assert not world.snapshot().robots[1].fallen  # the built-in robot beside it is unaffected


def test_head_moves_by_its_hlvs_name_and_the_camera_sees_the_opponent() -> None:
    world = _world()
    world.set_motor_position(RED_1, "HeadPan", 0.4)
    for _ in range(125):
        world.step()
    assert abs(world.read_position(RED_1, "HeadPanS") - 0.4) < 0.05
    world.set_motor_position(RED_1, "HeadPan", 0.0)
    for _ in range(125):
        world.step()
    with CameraRenderer(world, 320, 240) as renderer:
        image = np.frombuffer(renderer.render(RED_1), dtype=np.uint8).reshape(240, 320, 3)
    pixels = image.astype(int)
    b, g, r = pixels[:, :, 0], pixels[:, :, 1], pixels[:, :, 2]
    # B,G,R: the blue robot's body by its hue (the match light varies in brightness), below
    # the sky's rows
    bluish = (b > r + 40) & (b > g + 20) & (b > 90)
    assert bluish[60:].sum() > 200
    assert len(np.unique(image.reshape(-1, 3), axis=0)) > 50


def test_referee_parts_and_hull_bodies_are_tagged() -> None:
    world = _world()
    model = world.model
    names = [model.geom(g).name for g in world.index.robots[0].geoms]
    for part in ("foot", "hand", "arm", "head", "leg", "torso"):
        assert any(n.startswith(f"red_1/{part}:") for n in names), part
    for hull in ("hand_L", "hand_R", "foot_L", "foot_R"):
        assert model.body(f"red_1/{hull}").id > 0
    assert mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_CAMERA, "red_1/Camera") >= 0


def test_link_boxes_and_cleats_replace_the_models_own_collision_geoms() -> None:
    original = load_spec(load_manifest(WOLFGANG)).compile()
    own = [g for g in range(original.ngeom)
           if original.geom_contype[g] or original.geom_conaffinity[g]]  # fmt: skip
    links = {original.body(b).name for b in range(1, original.nbody)}
    world = _world()
    model = world.model
    geoms = world.index.robots[0].geoms
    colliding = [model.geom(g).name for g in geoms
                 if model.geom_contype[g] or model.geom_conaffinity[g]]  # fmt: skip
    # one box per link ("red_1/leg:l_knee"), the sole's cleats ("..._cleat_0"), none of the
    # authors' own shapes (which would be "red_1/leg:l_knee_3")
    for name in colliding:
        link = name.split(":", 1)[1]
        assert link in links or "_cleat_" in link, name
    assert 0 < len(colliding) < len(own)
    assert not any(DROPPED in model.geom(g).name for g in geoms)


def test_replay_scene_records_meshes_as_their_bounding_boxes() -> None:
    from simulator.replay.scene import scene_of

    world = _world()
    scene = scene_of(world.model, world.placements, world.field)
    visuals = [g for g in scene["geoms"] if g["name"].startswith("red_1/visual:torso_")]
    assert visuals and all(g["type"] == "box" for g in visuals)
    assert all(0.0 < max(g["size"]) < 0.2 for g in visuals)  # parts of a 0.8 m robot
