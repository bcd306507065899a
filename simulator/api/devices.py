"""The device interface the robot API server needs from the world.

:class:`DeviceWorld` is the subset of ``simulator.world.World`` used by the server (semantics as
HLVS: motors, position sensors, IMUs, foot force sensors and a head camera, each found by the
name ``devices(robot)`` gives it: the robot model's, as its team's robot file names it; the
built-in models' are the league's sample robot's, ``<motor>S``, ``Accelerometer``, ``Gyro``,
``Camera``). :class:`FakeDeviceWorld` implements it without MuJoCo for unit tests, with the
sample robot's names. The one-by-one reads (``read_accelerometer``, ``read_gyro``) are the
first IMU's; a robot with more IMUs is read by name through ``read_sensors``. A world may
also offer the batch forms ``set_motor_positions(robot, names, rads)`` and
``read_sensors(robot, names) -> flat values`` (``simulator.world.World`` does); sessions use them
when present, with the same results as the one-by-one calls.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any, Protocol

from contracts import RobotId, TeamColor

Vec3 = tuple[float, float, float]

MOTOR = "MOTOR"
POSITION_SENSOR = "POSITION_SENSOR"
ACCELEROMETER = "ACCELEROMETER"
GYRO = "GYRO"
CAMERA = "CAMERA"
FORCE = "FORCE"
SENSOR_KINDS = frozenset({POSITION_SENSOR, ACCELEROMETER, GYRO, CAMERA, FORCE})


def kind_name(kind: Any) -> str:
    """The upper-case name of a device kind (an enum member or a plain string)."""
    name = getattr(kind, "name", kind)
    return str(name).upper()


def robot_key(robot: RobotId) -> str:
    """The robot's name in results and logs: ``red-1``."""
    return f"{robot.team.value}-{robot.number}"


class DeviceWorld(Protocol):
    """What the server calls on the world; every call happens on the step thread."""

    @property
    def sim_time_ms(self) -> int: ...

    def devices(self, robot: RobotId) -> Mapping[str, Any]: ...

    def set_motor_position(self, robot: RobotId, name: str, rad: float) -> None: ...

    def set_motor_velocity(self, robot: RobotId, name: str, rad_s: float) -> None: ...

    def set_motor_torque(self, robot: RobotId, name: str, nm: float) -> None: ...

    def set_motor_pid(self, robot: RobotId, name: str, p: float, i: float, d: float) -> None: ...

    def read_position(self, robot: RobotId, sensor_name: str) -> float: ...

    def read_accelerometer(self, robot: RobotId) -> Vec3: ...

    def read_gyro(self, robot: RobotId) -> Vec3: ...

    def read_force(self, robot: RobotId, name: str) -> float: ...

    def camera_info(self, robot: RobotId) -> tuple[int, int, float]: ...

    def is_limp(self, robot: RobotId) -> bool: ...

    def is_removed(self, robot: RobotId) -> bool: ...


KID_MOTORS = (
    "Neck", "Head", "ShoulderL", "ArmUpperL", "ArmLowerL", "PelvYL", "PelvL", "LegUpperL",
    "LegLowerL", "AnkleL", "FootL", "PelvYR", "PelvR", "LegUpperR", "LegLowerR", "AnkleR",
    "FootR", "ShoulderR", "ArmUpperR", "ArmLowerR",
)  # fmt: skip
KID_FORCES = ("llb", "llf", "lrf", "lrb", "rlb", "rlf", "rrf", "rrb")


class FakeDeviceWorld:
    """A deterministic stand-in world: motors track their targets in one step.

    Positions move to the commanded target at each :meth:`step` (limp robots keep theirs);
    the accelerometer reads gravity, the gyro zero, force sensors a fixed share of the weight.
    Records every call in :attr:`calls` for assertions.
    """

    def __init__(self, robots: Sequence[RobotId], *, camera: tuple[int, int] = (320, 240)) -> None:
        self.robot_ids = tuple(robots)
        self.sim_time_ms = 0
        self.camera = camera
        self.targets: dict[RobotId, dict[str, float]] = {
            r: dict.fromkeys(KID_MOTORS, 0.0) for r in robots
        }
        self.positions: dict[RobotId, dict[str, float]] = {
            r: dict.fromkeys(KID_MOTORS, 0.0) for r in robots
        }
        self.limp: set[RobotId] = set()
        self.removed: set[RobotId] = set()
        self.calls: list[tuple[str, RobotId, str, tuple[float, ...]]] = []
        kinds: dict[str, str] = dict.fromkeys(KID_MOTORS, MOTOR)
        kinds.update({f"{m}S": POSITION_SENSOR for m in KID_MOTORS})
        kinds.update({"Accelerometer": ACCELEROMETER, "Gyro": GYRO, "Camera": CAMERA})
        kinds.update(dict.fromkeys(KID_FORCES, FORCE))
        self._kinds = kinds

    def step(self) -> None:
        self.sim_time_ms += 8
        for robot in self.robot_ids:
            if robot not in self.limp and robot not in self.removed:
                self.positions[robot].update(self.targets[robot])

    def devices(self, robot: RobotId) -> Mapping[str, Any]:
        return self._kinds

    def set_motor_position(self, robot: RobotId, name: str, rad: float) -> None:
        self.calls.append(("position", robot, name, (rad,)))
        self.targets[robot][name] = rad

    def set_motor_velocity(self, robot: RobotId, name: str, rad_s: float) -> None:
        self.calls.append(("velocity", robot, name, (rad_s,)))

    def set_motor_torque(self, robot: RobotId, name: str, nm: float) -> None:
        self.calls.append(("torque", robot, name, (nm,)))

    def set_motor_pid(self, robot: RobotId, name: str, p: float, i: float, d: float) -> None:
        self.calls.append(("pid", robot, name, (p, i, d)))

    def read_position(self, robot: RobotId, sensor_name: str) -> float:
        return self.positions[robot][sensor_name[:-1]]

    def read_accelerometer(self, robot: RobotId) -> Vec3:
        return (0.0, 0.0, 9.81)

    def read_gyro(self, robot: RobotId) -> Vec3:
        return (0.0, 0.0, 0.0)

    def read_force(self, robot: RobotId, name: str) -> float:
        return 5.0

    def camera_info(self, robot: RobotId) -> tuple[int, int, float]:
        return (self.camera[0], self.camera[1], 1.04)

    def is_limp(self, robot: RobotId) -> bool:
        return robot in self.limp

    def is_removed(self, robot: RobotId) -> bool:
        return robot in self.removed


class FakeCameraRenderer:
    """Renders a uniform image whose blue byte is the robot number (B, G, R order)."""

    def __init__(self, world: object, width: int, height: int) -> None:
        self.width = width
        self.height = height

    def render(self, robot: RobotId) -> bytes:
        red = 255 if robot.team is TeamColor.RED else 0
        return bytes((robot.number, 0, red)) * (self.width * self.height)
