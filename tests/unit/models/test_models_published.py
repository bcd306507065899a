"""Published humanoids, their files as their authors ship them and only a manifest added, pass
the official model check and stand in the world under their catalogue servos.

``published/`` keeps each robot's model file verbatim and, instead of its meshes (megabytes), a
box of each mesh's size (``mesh_boxes.json``), written as an STL file before the test:

- ``booster_k1``: BoosterRobotics/booster_assets ``robots/K1/K1_22dof.urdf`` at 486da0f
  (meshes next to the URDF, relative ``meshes/`` paths);
- ``booster_t1``: the same repository's ``robots/T1/T1_23dof.xml`` (an adult-size robot: its own
  free joint, a ground plane, lights, a skybox, actuators, sensors, ``meshdir="meshes/"``);
- ``menagerie_op3``: google-deepmind/mujoco_menagerie ``robotis_op3/op3.xml`` at 361161b
  (``meshdir="assets"``, default classes setting the mesh scale and the collision flags, an
  unnamed ``<freejoint/>``, contact exclusions, position actuators, no joint ranges);
- the Wolfgang of the examples (bit-bots/wolfgang_robot's URDF and meshes, unchanged).
"""

from __future__ import annotations

import json
import math
import shutil
import struct
from pathlib import Path

import numpy as np
import pytest

from contracts.ids import RobotId, TeamColor
from orchestrator.config.robot_models import check_model
from simulator.world import RobotPlacement, World
from simulator.world.types import DeviceKind

from .conftest import WOLFGANG

PUBLISHED = Path(__file__).resolve().parent / "published"
RED_1 = RobotId(TeamColor.RED, 1)


def write_box_stl(path: Path, box: list[float]) -> None:
    """A binary STL of the box ``[xmin, ymin, zmin, xmax, ymax, zmax]`` (12 triangles)."""
    lo, hi = np.array(box[:3], dtype=float), np.array(box[3:], dtype=float)
    corners = np.array([[(lo, hi)[i >> k & 1][k] for k in range(3)] for i in range(8)])
    faces = [(0, 2, 1), (1, 2, 3), (4, 5, 6), (5, 7, 6), (0, 1, 4), (1, 5, 4),
             (2, 6, 3), (3, 6, 7), (0, 4, 2), (2, 4, 6), (1, 3, 5), (3, 7, 5)]  # fmt: skip
    data = bytearray(80) + struct.pack("<I", len(faces))
    for a, b, c in faces:
        data += struct.pack("<12fH", 0, 0, 0, *corners[a], *corners[b], *corners[c], 0)
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_bytes(bytes(data))


def package(name: str, target: Path) -> Path:
    """A copy of ``published/<name>`` with its meshes written as boxes of their size."""
    folder = target / name
    shutil.copytree(PUBLISHED / name, folder)
    for boxes_file in folder.rglob("mesh_boxes.json"):
        for relative, box in json.loads(boxes_file.read_text())["boxes"].items():
            write_box_stl(boxes_file.parent / relative, box)
    return folder


def stands(
    folder: Path, *, field_class: str, p: float, seconds: float = 10.0
) -> tuple[bool, float]:
    """Whether the robot, placed in its standing pose with every motor's P at ``p``, is still up
    after ``seconds``, and how far its root drifted (m)."""
    world = World.create(
        field_class=field_class,
        robots=[RobotPlacement(id=RED_1, model=str(folder), x_m=-1.0, y_m=0.5, yaw_rad=0.0)],
        seed=5,
    )
    for name, kind in world.devices(RED_1).items():
        if kind is DeviceKind.MOTOR:
            world.set_motor_pid(RED_1, name, p, 0.0, 0.0)
    start = world.snapshot().robots[0].position
    for _ in range(round(seconds / 0.008)):
        world.step()
    end = world.snapshot().robots[0]
    return not end.fallen, math.dist(end.position, start)


ROBOTS = [
    ("booster_k1", "kid"),
    ("booster_t1", "adult"),
    ("menagerie_op3", "kid"),
]


@pytest.mark.parametrize(("name", "field_class"), ROBOTS)
def test_published_robot_passes_the_official_check_and_stands_at_p10_and_p30(
    tmp_path: Path, name: str, field_class: str
) -> None:
    folder = package(name, tmp_path)
    problems, measurements = check_model(folder, official=True)
    assert measurements is not None and measurements.size_class == field_class
    assert [str(p) for p in problems if p.severity == "error"] == []
    manifest = json.loads((folder / "robot_model.json").read_text())
    assert "joint_armature" not in manifest  # the servos' own reflected inertia
    for p in (10.0, 30.0):
        up, drift = stands(folder, field_class=field_class, p=p)
        assert up, f"{name} fell at P={p}"
        assert drift < 0.05, (name, p, drift)


def test_wolfgang_stands_at_p10_and_p30_with_its_servos_armature() -> None:
    manifest = json.loads((WOLFGANG / "robot_model.json").read_text())
    assert "joint_armature" not in manifest
    for p in (10.0, 30.0):
        up, drift = stands(WOLFGANG, field_class="kid", p=p)
        assert up and drift < 0.05, (p, drift)


def test_what_the_world_replaces_is_a_note_naming_the_element(tmp_path: Path) -> None:
    problems, _ = check_model(package("booster_t1", tmp_path), official=True)
    notes = {p.pointer: p.message for p in problems if p.severity == "note"}
    assert notes["<worldbody><geom name='ground' type='plane'>"].startswith("ignored: the ground")
    assert notes["<actuator>"].startswith("ignored (23 elements): the motors are the manifest's")
    assert "<sensor>" in notes and "<texture type='skybox'> x1" not in notes
    assert any(k.startswith("<worldbody><light") and k.endswith("x2") for k in notes)
    problems, _ = check_model(package("menagerie_op3", tmp_path), official=True)
    notes = {p.pointer: p.message for p in problems if p.severity == "note"}
    assert "self-collision follows the league's rule" in notes["<contact>"]


def test_robots_of_several_published_models_share_one_world(tmp_path: Path) -> None:
    """Two OP3 (whose file names a site ``torso`` and a camera) and a K1 and a T1 (both with a
    ``matplane`` material and ``texplane`` texture): names that are the file's, not the robot's,
    would repeat in the world."""
    op3, k1, t1 = (package(n, tmp_path) for n in ("menagerie_op3", "booster_k1", "booster_t1"))
    models = [op3, op3, k1, t1]
    world = World.create(
        field_class="kid",
        robots=[
            RobotPlacement(
                id=RobotId(TeamColor.RED if i % 2 == 0 else TeamColor.BLUE, i // 2 + 1),
                model=str(folder),
                x_m=-2.0 + 1.2 * i,
                y_m=0.0,
                yaw_rad=0.0,
            )
            for i, folder in enumerate(models)
        ],
        seed=1,
    )
    for _ in range(125):
        world.step()
    assert [r.fallen for r in world.snapshot().robots] == [False] * 4


@pytest.mark.parametrize("name", [name for name, _ in ROBOTS])
def test_published_manifests_follow_the_schema(name: str) -> None:
    import jsonschema

    schema = Path(__file__).resolve().parents[3] / "configs" / "schemas" / "robot_model.schema.json"
    manifest = json.loads((PUBLISHED / name / "robot_model.json").read_text())
    jsonschema.validate(manifest, json.loads(schema.read_text()))
