"""The names a robot answers to on the robot API, and where its sensors live in its MJCF.

The league's robot API finds a device by the name its Webots robot file (PROTO) gives it; each
robot file names its own: the league's sample robot (``Darwin-opHinge2Robocup.proto``) has
``Neck`` with the position sensor ``NeckS``, ``Accelerometer``, ``Gyro`` and ``Camera``, while
bit-bots' Wolfgang (``WolfgangRobocup/Wolfgang.proto``) has ``HeadPan`` with ``HeadPan_sensor``,
two IMUs (``imu accelerometer`` / ``imu gyro`` in the trunk, ``imu_head accelerometer`` /
``imu_head gyro`` in the head) and ``camera``. The built-in models answer to the sample robot's
names (:meth:`DeviceNames.league`); a team model to those of its manifest
(:mod:`simulator.world.robots.team.devices`).

In the MJCF the first IMU's sensors are ``<prefix>/Accelerometer`` and ``<prefix>/Gyro`` (site
``<prefix>/site:imu``), the k-th one's (k >= 1) ``<prefix>/imu<k>:Accelerometer`` and
``<prefix>/imu<k>:Gyro`` (site ``<prefix>/site:imu<k>``), whatever their names on the API.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

from simulator.world.types import DeviceKind

LEAGUE_SENSOR_SUFFIX = "S"
LEAGUE_ACCELEROMETER = "Accelerometer"
LEAGUE_GYRO = "Gyro"
LEAGUE_CAMERA = "Camera"


def imu_site(k: int) -> str:
    """The MJCF site (without the robot's prefix) of the k-th IMU."""
    return "site:imu" if k == 0 else f"site:imu{k}"


def imu_sensor(k: int, kind: DeviceKind) -> str:
    """The MJCF sensor (without the robot's prefix) of the k-th IMU's accelerometer or gyro."""
    base = LEAGUE_ACCELEROMETER if kind is DeviceKind.ACCELEROMETER else LEAGUE_GYRO
    return base if k == 0 else f"imu{k}:{base}"


@dataclass(frozen=True, slots=True, kw_only=True)
class ImuNames:
    """One IMU: its accelerometer's and its gyro's device names."""

    accelerometer: str = LEAGUE_ACCELEROMETER
    gyro: str = LEAGUE_GYRO


@dataclass(frozen=True, slots=True, kw_only=True)
class DeviceNames:
    """Every device name of one robot model, by kind, and the MJCF sensors behind them.

    ``motors`` and ``position_sensors`` are in the model's ``motor_names`` order (the k-th
    position sensor measures the k-th motor's joint); ``imus[0]`` is the IMU the world's
    ``read_accelerometer`` / ``read_gyro`` read; ``force_mjcf[k]`` is the MJCF sensor (without
    the robot's prefix) of ``forces[k]``.
    """

    motors: tuple[str, ...]
    position_sensors: tuple[str, ...]
    imus: tuple[ImuNames, ...]
    camera: str
    forces: tuple[str, ...]
    force_mjcf: tuple[str, ...]

    @classmethod
    def league(
        cls,
        motors: Sequence[str],
        *,
        camera: str = LEAGUE_CAMERA,
        forces: Sequence[str] = (),
    ) -> DeviceNames:
        """The league's sample robot's naming: ``<motor>S``, ``Accelerometer``, ``Gyro``."""
        return cls(
            motors=tuple(motors),
            position_sensors=tuple(f"{m}{LEAGUE_SENSOR_SUFFIX}" for m in motors),
            imus=(ImuNames(),),
            camera=camera,
            forces=tuple(forces),
            force_mjcf=tuple(forces),
        )

    def kinds(self) -> dict[str, DeviceKind]:
        """Device name -> kind, every device of the robot (motors first, then position
        sensors, accelerometers, gyros, the camera and the force sensors)."""
        out = dict.fromkeys(self.motors, DeviceKind.MOTOR)
        out.update(dict.fromkeys(self.position_sensors, DeviceKind.POSITION_SENSOR))
        out.update(dict.fromkeys((i.accelerometer for i in self.imus), DeviceKind.ACCELEROMETER))
        out.update(dict.fromkeys((i.gyro for i in self.imus), DeviceKind.GYRO))
        out[self.camera] = DeviceKind.CAMERA
        out.update(dict.fromkeys(self.forces, DeviceKind.FORCE))
        return out

    def by_kind(self) -> dict[DeviceKind, tuple[str, ...]]:
        """The names of each kind, in the order of :meth:`kinds` (for listings)."""
        out: dict[DeviceKind, tuple[str, ...]] = {}
        for name, kind in self.kinds().items():
            out[kind] = (*out.get(kind, ()), name)
        return out
