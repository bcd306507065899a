"""The Wolfgang model package shipped as an example, and small model files written by tests."""

from __future__ import annotations

import json
import shutil
from pathlib import Path
from typing import Any

import pytest

WOLFGANG = Path(__file__).resolve().parents[3] / "configs" / "examples" / "robots" / "wolfgang"


@pytest.fixture
def wolfgang_copy(tmp_path: Path) -> Path:
    """A copy of the Wolfgang package that a test may break."""
    target = tmp_path / "wolfgang"
    shutil.copytree(WOLFGANG, target)
    return target


def edit_manifest(folder: Path, **changes: Any) -> None:
    path = folder / "robot_model.json"
    manifest = json.loads(path.read_text())
    manifest.update(changes)
    path.write_text(json.dumps(manifest))


def box_robot(
    folder: Path,
    *,
    height_m: float,
    joints: bool = True,
    arms_sideways_m: float = 0.0,
    motor: dict[str, Any] | None = None,
) -> Path:
    """An MJCF stick robot ``height_m`` tall (legs 0.45 H, head 0.2 H) with its manifest (which
    names five motors, whether or not the model has ``joints``, each a catalogue MX-64 unless
    ``motor`` gives other fields). ``arms_sideways_m``: arms that long held straight out
    sideways instead of hanging down."""
    folder.mkdir(parents=True, exist_ok=True)
    h = height_m
    leg, head = 0.45 * h, 0.2 * h
    trunk = h - leg - head

    def hinge(name: str) -> str:
        return f'<joint name="{name}" type="hinge" axis="0 1 0" range="-1 1"/>' if joints else ""

    legs = "".join(
        f'<body name="hip_{s}" pos="0 {y} {leg}">{hinge("hip_" + s)}'
        f'<geom type="capsule" fromto="0 0 0 0 0 {-leg + 0.03}" size="0.03"/>'
        f'<body name="foot_{s}" pos="0 0 {-leg + 0.01}">'
        f'<geom type="box" size="0.08 0.04 0.01" pos="0.02 0 0"/></body></body>'
        for s, y in (("l", 0.06), ("r", -0.06))
    )
    arm = (0.0, 0.0, -trunk * 0.8)

    def reach(side: float) -> tuple[float, float, float]:
        return (0.0, side * arms_sideways_m, 0.0) if arms_sideways_m else arm

    arms = "".join(
        f'<body name="arm_{s}" pos="0 {y} {leg + trunk * 0.9}">{hinge("arm_" + s)}'
        f'<geom type="capsule" fromto="0 0 0 {" ".join(map(str, reach(sign)))}" size="0.02"/>'
        f'<body name="hand_{s}" pos="{" ".join(map(str, reach(sign)))}">'
        f'<geom type="sphere" size="0.025"/></body></body>'
        for s, y, sign in (("l", 0.15, 1.0), ("r", -0.15, -1.0))
    )
    xml = f"""<mujoco model="box">
<worldbody><body name="base">
 <geom type="box" size="0.06 0.1 {trunk / 2}" pos="0 0 {leg + trunk / 2}" mass="2"/>
 <body name="imu" pos="0 0 {leg + trunk / 2}"/>
 {legs}{arms}
 <body name="head" pos="0 0 {leg + trunk}">{hinge("neck")}
  <geom type="box" size="0.05 0.05 {head / 2}" pos="0 0 {head / 2}"/>
  <body name="cam" pos="0.05 0 {head / 2}"/>
 </body>
</body></worldbody></mujoco>"""
    (folder / "robot.xml").write_text(xml)
    motors = [
        {"joint": j, **(motor if motor is not None else {"servo": "MX-64@14.8V"})}
        for j in ("hip_l", "hip_r", "arm_l", "arm_r", "neck")
    ]
    manifest = {
        "format_version": 1,
        "name": "box",
        "class": "kid",
        "model_file": "robot.xml",
        "motors": motors,
        "imu": {"link": "imu"},
        "cameras": [{"link": "cam", "width": 320, "height": 240, "fov_rad": 1.0}],
        "force_sensors": {},
        "parts": {
            "foot": ["foot_l", "foot_r"],
            "leg": ["hip_l", "hip_r"],
            "arm": ["arm_l", "arm_r"],
            "hand": ["hand_l", "hand_r"],
            "head": ["head"],
        },
        "hands": {"left": "hand_l", "right": "hand_r"},
        "feet": {"left": "foot_l", "right": "foot_r"},
    }
    (folder / "robot_model.json").write_text(json.dumps(manifest))
    return folder
