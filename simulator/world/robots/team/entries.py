"""The manifest of a team robot model as :func:`simulator.world.robots.team.manifest.load_manifest`
gives it, validated: its motors, IMUs, cameras and jersey, paths absolute."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

from contracts import JSONObject


@dataclass(frozen=True, slots=True, kw_only=True)
class MotorEntry:
    """One joint of the model file driven as an HLVS motor: a catalogue servo (``servo``, its
    figures unless the entry gives lower ones) or free-form figures (``servo`` empty: allowed
    with a warning in friendlies, refused in official matches)."""

    joint: str  # joint name in the model file
    name: str  # HLVS device name (position sensor: name + sensor suffix)
    servo: str  # catalogue id as written in the manifest, or ""
    max_torque_nm: float | None  # as written (None: the servo's)
    max_velocity_rad_s: float | None
    free_gains: tuple[str, ...] = ()  # the free-form keys the entry sets (kp, kv)
    range_rad: tuple[float, float] | None = None  # the joint's range where the file has none
    sensor: str = ""  # its position sensor's device name as written ("": name + sensor_suffix)


@dataclass(frozen=True, slots=True, kw_only=True)
class ImuEntry:
    """One IMU: the link it sits in (at the link's origin, axes as the link's) and the device
    names of its accelerometer and gyro. ``where``: its JSON pointer (``/imu`` or ``/imu/K``)."""

    link: str
    accelerometer: str = "Accelerometer"
    gyro: str = "Gyro"
    where: str = "/imu"


@dataclass(frozen=True, slots=True, kw_only=True)
class CameraEntry:
    name: str
    link: str
    width: int
    height: int
    fov_rad: float  # horizontal
    pos_m: tuple[float, float, float] = (0.0, 0.0, 0.0)  # in the link frame; looks along link +x


@dataclass(frozen=True, slots=True, kw_only=True)
class JerseyPlate:
    """One side of a team model's jersey: a plate centred at ``pos_m`` (link frame), ``size_m``
    wide (along the link's y) and high (along its z)."""

    pos_m: tuple[float, float, float]
    size_m: tuple[float, float]


@dataclass(frozen=True, slots=True, kw_only=True)
class JerseyEntry:
    """Where a team model wears the team's jersey with the player number (the league's robots
    wear a shirt texture per team colour and number, hlvs_webots
    ``protos/robots/RoboCupRobot/RobotisJersey.proto``): plates fixed to ``link``, the front
    facing the link's +x, the back its -x, the number upright along its +z."""

    link: str
    front: JerseyPlate | None
    back: JerseyPlate | None


@dataclass(frozen=True, slots=True, kw_only=True)
class Manifest:
    """A validated ``robot_model.json``; paths are absolute."""

    path: Path
    name: str
    field_class: str
    model_file: Path
    packages: dict[str, Path]
    motors: tuple[MotorEntry, ...]
    sensor_suffix: str
    imu_link: str
    cameras: tuple[CameraEntry, ...]
    force_sensors: dict[str, str]  # HLVS name -> link
    parts: dict[str, str]  # link -> part (its subtree inherits it)
    hands: tuple[str, str]  # left, right link
    feet: tuple[str, str]
    collision: str
    standing_pose_rad: dict[str, float]  # HLVS motor name -> rad; others 0
    joint_damping: float | None = None
    joint_armature: float | None = None
    joint_frictionloss: float | None = None
    imus: tuple[ImuEntry, ...] = ()  # every IMU, the first in ``imu_link``
    jersey: JerseyEntry | None = None  # None: the robot wears no jersey
    extra: JSONObject = field(default_factory=dict)  # keys this build does not read

    @property
    def folder(self) -> Path:
        return self.path.parent
