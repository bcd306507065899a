"""The manifest of a team robot model (``robot_model.json``): how a URDF or MJCF file maps to the
league's robot API.

A model package is a folder with the manifest, the model file and its meshes::

    robot_model.json
    wolfgang_description/urdf/robot.urdf      (``model_file``, relative to the manifest)
    wolfgang_description/urdf/*.stl           (``package://wolfgang_description/...``)

Every problem is a :class:`ModelProblem` naming the file, the JSON pointer (or the XML element),
the value and what was expected; :func:`load_manifest` raises :class:`ModelError` with all of them.
"""

from __future__ import annotations

import json
import math
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from contracts import huge_integer_reason, huge_integers, parse_int
from simulator.errors import ModelError, ModelProblem
from simulator.world.robots.team.devices import device_name_problems
from simulator.world.robots.team.entries import (
    CameraEntry,
    ImuEntry,
    JerseyEntry,
    JerseyPlate,
    Manifest,
    MotorEntry,
)
from simulator.world.robots.team.package import LIMITS, inside, outside_reason, size_problem
from simulator.world.servos import find_servo, servo_ids

MANIFEST_NAME = "robot_model.json"
FORMAT_VERSION = 1
PART_NAMES = ("foot", "hand", "arm", "head", "torso", "leg")
COLLISION_MODES = ("link-boxes", "as-is")
FIELD_CLASSES = ("kid", "adult")


class _Reader:
    def __init__(self, path: Path) -> None:
        self.path = path
        self.problems: list[ModelProblem] = []

    def problem(self, pointer: str, reason: str) -> None:
        self.problems.append(ModelProblem(source=str(self.path), where=pointer, reason=reason))

    def get(
        self,
        obj: Mapping[str, object],  # a JSON object of the manifest, not yet checked
        key: str,
        kind: type | tuple[type, ...],
        pointer: str,
        *,
        required: bool = True,
        default: Any = None,
    ) -> Any:
        if key not in obj:
            if required:
                self.problem(f"{pointer}/{key}", f"missing; expected {_kind_name(kind)}")
            return default
        value = obj[key]
        if isinstance(value, bool) and bool not in _as_tuple(kind):
            self.problem(f"{pointer}/{key}", f"{value!r} is not {_kind_name(kind)}")
            return default
        if not isinstance(value, kind):
            self.problem(f"{pointer}/{key}", f"{value!r} is not {_kind_name(kind)}")
            return default
        return value

    def positive(
        self,
        obj: Mapping[str, object],  # a JSON object of the manifest, not yet checked
        key: str,
        pointer: str,
        *,
        required: bool = True,
        default: float | None = None,
    ) -> float | None:
        value = self.get(obj, key, (int, float), pointer, required=required, default=default)
        if value is None:
            return None
        if not math.isfinite(float(value)) or float(value) <= 0:
            self.problem(f"{pointer}/{key}", f"{value!r} must be a positive number")
            return default
        return float(value)


def _as_tuple(kind: type | tuple[type, ...]) -> tuple[type, ...]:
    return kind if isinstance(kind, tuple) else (kind,)


def _kind_name(kind: type | tuple[type, ...]) -> str:
    names = {
        int: "an integer",
        float: "a number",
        str: "a string",
        dict: "an object",
        list: "an array",
        bool: "true or false",
    }
    return " or ".join(dict.fromkeys(names.get(k, k.__name__) for k in _as_tuple(kind)))


_KNOWN_KEYS = {
    "format_version",
    "name",
    "class",
    "model_file",
    "packages",
    "motors",
    "sensor_suffix",
    "imu",
    "cameras",
    "force_sensors",
    "parts",
    "hands",
    "feet",
    "collision",
    "joint_damping",
    "joint_armature",
    "joint_frictionloss",
    "description",
    "standing_pose_rad",
    "jersey",
}
_JOINT_KEYS = ("joint_damping", "joint_armature", "joint_frictionloss")
JERSEY_MAX_M = 0.5  # the largest plate side, and the farthest a plate's centre from its link


def load_manifest(folder_or_file: Path) -> Manifest:
    """Read and validate a model package's manifest. Raises :class:`ModelError`.

    A file that cannot be read as one JSON object stops at its first problem
    (:func:`_read_raw`); the fields are then read in the manifest's order, every problem
    collected, and the device names checked last, on the whole manifest."""
    path, raw = _read_raw(folder_or_file)
    folder = path.parent
    r = _Reader(path)
    for key in sorted(set(raw) - _KNOWN_KEYS):
        r.problem(f"/{key}", f"unknown field; known fields: {', '.join(sorted(_KNOWN_KEYS))}")
    version = r.get(raw, "format_version", int, "")
    if version is not None and version != FORMAT_VERSION:
        r.problem(
            "/format_version",
            f"{version} is not a version this program reads (expected {FORMAT_VERSION})",
        )
    name = r.get(raw, "name", str, "") or ""
    field_class = r.get(raw, "class", str, "") or "kid"
    if field_class not in FIELD_CLASSES:
        r.problem("/class", f"{field_class!r} is not one of {', '.join(FIELD_CLASSES)}")
    model_file = _model_file(r, raw, folder)
    packages = _packages(r, raw, folder)
    motors = _motors(r, raw)
    sensor_suffix = r.get(raw, "sensor_suffix", str, "", required=False, default="S")
    imus = _imus(r, raw)
    cameras = _cameras(r, raw)
    forces = r.get(raw, "force_sensors", dict, "", required=False, default={}) or {}
    for key, link in forces.items():
        if not isinstance(link, str):
            r.problem(f"/force_sensors/{key}", f"{link!r} is not a string (a link name)")
    parts = _parts(r, raw)
    hands = _pair(r, raw, "hands")
    feet = _pair(r, raw, "feet")
    collision = r.get(raw, "collision", str, "", required=False, default="link-boxes")
    if collision not in COLLISION_MODES:
        r.problem("/collision", f"{collision!r} is not one of {', '.join(COLLISION_MODES)}")
    standing = _standing_pose(r, raw, motors)
    damping, armature, friction = (_non_negative(r, raw, key) for key in _JOINT_KEYS)
    jersey = _jersey(r, raw)
    if r.problems:
        raise ModelError(r.problems)
    manifest = Manifest(
        path=path,
        name=name,
        field_class=field_class,
        model_file=model_file,
        packages=packages,
        motors=motors,
        sensor_suffix=sensor_suffix,
        imu_link=imus[0].link,
        cameras=cameras,
        force_sensors={str(k): str(v) for k, v in forces.items()},
        parts=parts,
        hands=hands,
        feet=feet,
        collision=str(collision),
        standing_pose_rad={str(k): float(v) for k, v in standing.items()},
        joint_damping=None if damping is None else float(damping),
        joint_armature=None if armature is None else float(armature),
        joint_frictionloss=None if friction is None else float(friction),
        imus=imus,
        jersey=jersey,
    )
    problems = device_name_problems(manifest)
    if problems:
        raise ModelError(problems)
    return manifest


def _read_raw(folder_or_file: Path) -> tuple[Path, dict[str, object]]:
    """The manifest's absolute path and its JSON object: inside its folder, there, within its
    size limit, JSON without oversized integers, an object. Raises :class:`ModelError` with the
    first problem found."""
    if folder_or_file.is_dir():
        folder, name = folder_or_file.resolve(), MANIFEST_NAME
    else:
        folder, name = folder_or_file.parent.resolve(), folder_or_file.name
    path = folder / name
    if not inside(folder, path):
        raise ModelError([ModelProblem(source=str(path), where="", reason=outside_reason(name))])
    if not path.is_file():
        raise ModelError(
            [
                ModelProblem(
                    source=str(path),
                    where="",
                    reason=f"no {MANIFEST_NAME} here (a model package is a "
                    f"folder with {MANIFEST_NAME} and the model file)",
                )
            ]
        )
    too_big = size_problem(str(path), "", "the manifest", path, LIMITS.manifest_bytes)
    if too_big is not None:
        raise ModelError([too_big])
    try:
        raw = json.loads(path.read_text(encoding="utf-8"), parse_int=parse_int)
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise ModelError(
            [ModelProblem(source=str(path), where="", reason=f"not JSON: {exc}")]
        ) from None
    huge = huge_integers(raw)
    if huge:
        raise ModelError([
            ModelProblem(source=str(path), where=pointer,
                         reason="{} (expected {})".format(*huge_integer_reason(literal)))
            for pointer, literal in huge
        ])
    if not isinstance(raw, dict):
        raise ModelError([ModelProblem(source=str(path), where="", reason="expected an object")])
    return path, raw


def _model_file(r: _Reader, raw: Mapping[str, object], folder: Path) -> Path:
    """``/model_file`` resolved: inside the package, there, a URDF or MJCF file."""
    model_rel = r.get(raw, "model_file", str, "") or ""
    model_file = (folder / model_rel).resolve()
    if model_rel and not inside(folder, folder / model_rel):
        r.problem("/model_file", outside_reason(repr(model_rel)))
    elif model_rel and not model_file.is_file():
        r.problem("/model_file", f"{model_rel!r}: no such file ({model_file})")
    elif model_rel and model_file.suffix.lower() not in (".urdf", ".xml", ".mjcf"):
        r.problem("/model_file", f"{model_rel!r}: expected a .urdf, .xml or .mjcf file")
    return model_file


def _packages(r: _Reader, raw: Mapping[str, object], folder: Path) -> dict[str, Path]:
    """``/packages``: ROS package name -> its folder inside the model package."""
    packages: dict[str, Path] = {}
    for pkg, rel in (r.get(raw, "packages", dict, "", required=False, default={}) or {}).items():
        if not isinstance(rel, str):
            r.problem(f"/packages/{pkg}", f"{rel!r} is not a string (a folder)")
            continue
        if not inside(folder, folder / rel):
            r.problem(f"/packages/{pkg}", outside_reason(repr(rel)))
            continue
        package = (folder / rel).resolve()
        if not package.is_dir():
            r.problem(f"/packages/{pkg}", f"{rel!r}: no such folder ({package})")
        packages[pkg] = package
    return packages


def _parts(r: _Reader, raw: Mapping[str, object]) -> dict[str, str]:
    """``/parts`` turned round: link -> body part."""
    parts: dict[str, str] = {}
    for part, links in (r.get(raw, "parts", dict, "") or {}).items():
        if part not in PART_NAMES:
            r.problem(f"/parts/{part}", f"unknown part; expected one of {', '.join(PART_NAMES)}")
            continue
        if not isinstance(links, list) or not all(isinstance(x, str) for x in links):
            r.problem(f"/parts/{part}", "expected an array of link names")
            continue
        for link in links:
            parts[link] = part
    return parts


def _standing_pose(
    r: _Reader, raw: Mapping[str, object], motors: tuple[MotorEntry, ...]
) -> dict[str, Any]:
    """``/standing_pose_rad`` as written: motor names of ``/motors``, numbers."""
    standing: dict[str, Any] = (
        r.get(raw, "standing_pose_rad", dict, "", required=False, default={}) or {}
    )
    motor_names = {m.name for m in motors}
    for key, value in standing.items():
        if key not in motor_names:
            r.problem(f"/standing_pose_rad/{key}", "not the name of a motor in /motors")
        elif isinstance(value, bool) or not isinstance(value, (int, float)):
            r.problem(f"/standing_pose_rad/{key}", f"{value!r} is not a number (rad)")
    return standing


def _non_negative(r: _Reader, raw: Mapping[str, object], key: str) -> float | None:
    value = r.get(raw, key, (int, float), "", required=False)
    if value is None:
        return None
    if not math.isfinite(float(value)) or float(value) < 0:
        r.problem(f"/{key}", f"{value!r} must be a number >= 0")
        return None
    return float(value)


def _motors(r: _Reader, raw: Mapping[str, object]) -> tuple[MotorEntry, ...]:
    entries = r.get(raw, "motors", list, "") or []
    if not entries and "motors" in raw:
        r.problem("/motors", "no motors: expected at least one joint driven as a motor")
    motors = []
    seen: dict[str, int] = {}
    for i, entry in enumerate(entries):
        p = f"/motors/{i}"
        if not isinstance(entry, dict):
            r.problem(p, "expected an object with joint, name, kp, max_torque_nm ...")
            continue
        joint = r.get(entry, "joint", str, p) or ""
        name = r.get(entry, "name", str, p, required=False, default=joint) or joint
        if name in seen:
            r.problem(f"{p}/name", f"{name!r} is also the name of /motors/{seen[name]}")
        seen[name] = i
        servo_name = r.get(entry, "servo", str, p, required=False, default="") or ""
        if servo_name and find_servo(servo_name) is None:
            r.problem(
                f"{p}/servo",
                f"{servo_name!r} is not in the league servo catalogue; known: "
                f"{', '.join(servo_ids())}",
            )
        required = not servo_name
        torque = r.positive(entry, "max_torque_nm", p, required=required)
        velocity = r.positive(entry, "max_velocity_rad_s", p, required=required)
        range_rad = _range(r, entry, p)
        sensor = r.get(entry, "sensor", str, p, required=False, default="") or ""
        gains = tuple(k for k in ("kp", "kv") if k in entry)
        for key in gains:
            value = entry[key]
            if isinstance(value, bool) or not isinstance(value, (int, float)):
                r.problem(f"{p}/{key}", f"{value!r} is not a number")
        if required and (torque is None or velocity is None):
            continue
        motors.append(
            MotorEntry(
                joint=joint,
                name=name,
                servo=servo_name,
                max_torque_nm=torque,
                max_velocity_rad_s=velocity,
                free_gains=gains,
                range_rad=range_rad,
                sensor=sensor,
            )
        )
    return tuple(motors)


def _range(r: _Reader, entry: Mapping[str, object], pointer: str) -> tuple[float, float] | None:
    """A motor's ``range_rad``: ``[lower, upper]`` in rad, lower below upper (or None)."""
    value = entry.get("range_rad")
    if value is None:
        return None
    if (
        isinstance(value, list)
        and len(value) == 2
        and all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in value)
        and all(math.isfinite(float(v)) for v in value)
        and float(value[0]) < float(value[1])
    ):
        return (float(value[0]), float(value[1]))
    r.problem(f"{pointer}/range_rad", f"{value!r} is not [lower, upper] in rad with lower < upper")
    return None


def _imus(r: _Reader, raw: Mapping[str, object]) -> tuple[ImuEntry, ...]:
    """``imu``: one IMU (an object) or several (an array of objects, the first the trunk's)."""
    value = r.get(raw, "imu", (dict, list), "")
    entries: list[tuple[str, object]] = (
        [(f"/imu/{k}", e) for k, e in enumerate(value)]
        if isinstance(value, list)
        else [("/imu", value if value is not None else {})]
    )
    if not entries:
        r.problem("/imu", "an empty array; expected at least one IMU")
    imus = []
    for k, (p, entry) in enumerate(entries):
        if not isinstance(entry, dict):
            r.problem(p, "expected an object with link (and accelerometer, gyro: device names)")
            continue
        for key in sorted(set(entry) - {"link", "accelerometer", "gyro"}):
            r.problem(f"{p}/{key}", "unknown field; known fields: accelerometer, gyro, link")
        link = r.get(entry, "link", str, p) or ""
        # the first IMU answers to the league's names unless it names its own; others must
        names = [
            r.get(entry, key, str, p, required=k > 0, default=default if k == 0 else "")
            for key, default in (("accelerometer", "Accelerometer"), ("gyro", "Gyro"))
        ]
        accelerometer, gyro = (n if n is not None else "" for n in names)
        imus.append(ImuEntry(link=link, accelerometer=accelerometer, gyro=gyro, where=p))
    return tuple(imus) or (ImuEntry(link=""),)


def _cameras(r: _Reader, raw: Mapping[str, object]) -> tuple[CameraEntry, ...]:
    cameras = []
    for i, entry in enumerate(r.get(raw, "cameras", list, "") or []):
        p = f"/cameras/{i}"
        if not isinstance(entry, dict):
            r.problem(p, "expected an object with name, link, width, height, fov_rad")
            continue
        name = r.get(entry, "name", str, p, required=False, default="Camera") or "Camera"
        link = r.get(entry, "link", str, p) or ""
        width = r.get(entry, "width", int, p)
        height = r.get(entry, "height", int, p)
        fov = r.positive(entry, "fov_rad", p)
        pos = r.get(entry, "pos_m", list, p, required=False, default=[0.0, 0.0, 0.0])
        if not (
            isinstance(pos, list)
            and len(pos) == 3
            and all(isinstance(v, (int, float)) for v in pos)
        ):
            r.problem(f"{p}/pos_m", f"{pos!r} is not [x, y, z] in metres")
            pos = [0.0, 0.0, 0.0]
        for key, value in (("width", width), ("height", height)):
            if value is not None and not 1 <= value <= 4096:
                r.problem(f"{p}/{key}", f"{value} pixels is outside 1..4096")
        if width is None or height is None or fov is None:
            continue
        cameras.append(
            CameraEntry(
                name=name,
                link=link,
                width=width,
                height=height,
                fov_rad=fov,
                pos_m=(float(pos[0]), float(pos[1]), float(pos[2])),
            )
        )
    return tuple(cameras)


def _jersey(r: _Reader, raw: Mapping[str, object]) -> JerseyEntry | None:
    """``jersey``: the link that wears it and its ``front`` and ``back`` plates (one at least)."""
    entry = r.get(raw, "jersey", dict, "", required=False)
    if entry is None:
        return None
    for key in sorted(set(entry) - {"link", "front", "back"}):
        r.problem(f"/jersey/{key}", "unknown field; known fields: back, front, link")
    link = r.get(entry, "link", str, "/jersey") or ""
    if "front" not in entry and "back" not in entry:
        r.problem("/jersey", "no plate; expected front, back or both")
    front, back = (_plate(r, entry, side) for side in ("front", "back"))
    return JerseyEntry(link=link, front=front, back=back)


def _plate(r: _Reader, entry: Mapping[str, object], side: str) -> JerseyPlate | None:
    p = f"/jersey/{side}"
    plate = r.get(entry, side, dict, "/jersey", required=False)
    if plate is None:
        return None
    for key in sorted(set(plate) - {"pos_m", "size_m"}):
        r.problem(f"{p}/{key}", "unknown field; known fields: pos_m, size_m")
    pos = r.get(plate, "pos_m", list, p)
    size = r.get(plate, "size_m", list, p)
    numbers = (int, float)
    if pos is not None and not (
        len(pos) == 3
        and all(isinstance(v, numbers) and not isinstance(v, bool) for v in pos)
        and all(math.isfinite(float(v)) and abs(float(v)) <= JERSEY_MAX_M for v in pos)
    ):
        r.problem(
            f"{p}/pos_m",
            f"{pos!r} is not [x, y, z] in metres, each within {JERSEY_MAX_M:g} of the link",
        )
        pos = None
    if size is not None and not (
        len(size) == 2
        and all(isinstance(v, numbers) and not isinstance(v, bool) for v in size)
        and all(math.isfinite(float(v)) and 0 < float(v) <= JERSEY_MAX_M for v in size)
    ):
        r.problem(
            f"{p}/size_m",
            f"{size!r} is not [width, height] in metres, each above 0 and at most "
            f"{JERSEY_MAX_M:g}",
        )
        size = None
    if pos is None or size is None:
        return None
    return JerseyPlate(
        pos_m=(float(pos[0]), float(pos[1]), float(pos[2])),
        size_m=(float(size[0]), float(size[1])),
    )


def _pair(r: _Reader, raw: Mapping[str, object], key: str) -> tuple[str, str]:
    obj = r.get(raw, key, dict, "") or {}
    left = r.get(obj, "left", str, f"/{key}") or ""
    right = r.get(obj, "right", str, f"/{key}") or ""
    return (left, right)
