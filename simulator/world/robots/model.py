"""Robot model descriptions: motors, sensors and the MJCF they produce."""

from __future__ import annotations

import math
from dataclasses import dataclass

from robot.geometry import CAMERA_FOV_RAD, HumanoidGeometry

FORCE_SENSORS = ("llb", "llf", "lrf", "lrb", "rlb", "rlf", "rrf", "rrb")
"""Sole corner force sensors: first letter foot (l/r), then side (l/r), then back/front."""



@dataclass(frozen=True, slots=True, kw_only=True)
class MotorSpec:
    """One position-controlled motor (a hinge joint and its actuator)."""

    name: str
    lower_rad: float
    upper_rad: float
    kp_nm_per_rad: float
    kv_nm_s_per_rad: float  # velocity feedback of the position controller
    max_torque_nm: float
    max_velocity_rad_s: float
    # the position sensor's resolution: 2 pi / 4096 rad, the 4096-count encoder of the league's
    # Dynamixel servos (:mod:`simulator.world.sensor_noise`)
    encoder_resolution_rad: float = 2.0 * math.pi / 4096.0


@dataclass(frozen=True, slots=True, kw_only=True)
class CameraSpec:
    name: str = "Camera"
    width: int = 320
    height: int = 240
    fov_rad: float = CAMERA_FOV_RAD  # horizontal


@dataclass(frozen=True, slots=True, kw_only=True)
class RobotMjcf:
    """MJCF fragments of one robot, to be placed in the matching sections of the world."""

    body: str
    actuators: str
    sensors: str
    assets: str = ""  # <asset> children (meshes) shared by every robot of the same model
    asset_key: str = ""  # robots with the same key share one copy of ``assets``


class MotorLookup:
    """Motor names and lookup by name, shared by the built-in and the team models."""

    __slots__ = ()
    motors: tuple[MotorSpec, ...]

    @property
    def motor_names(self) -> tuple[str, ...]:
        return tuple(m.name for m in self.motors)

    def motor(self, name: str) -> MotorSpec:
        for motor in self.motors:
            if motor.name == name:
                return motor
        raise KeyError(name)


@dataclass(frozen=True, slots=True, kw_only=True)
class RobotModel(MotorLookup):
    """A built-in robot model: its shape, motors and sensors."""

    name: str
    field_class: str  # "kid" | "adult"
    geometry: HumanoidGeometry
    motors: tuple[MotorSpec, ...]
    joint_damping: float
    joint_armature: float
    camera: CameraSpec = CameraSpec()
    force_sensors: tuple[str, ...] = FORCE_SENSORS

    @property
    def standing_height_m(self) -> float:
        return self.geometry.standing_height_m

    @property
    def standing_pose_rad(self) -> tuple[float, ...]:
        """Joint positions (``motor_names`` order) the robot stands in when placed: all zero."""
        return (0.0,) * len(self.motors)

    def mjcf(
        self,
        *,
        prefix: str,
        rgba: str,
        contype: int,
        conaffinity: int,
        pose: tuple[float, float, float],
    ) -> RobotMjcf:
        from simulator.world.robots.humanoid import build_humanoid

        return build_humanoid(
            self, prefix=prefix, rgba=rgba, contype=contype, conaffinity=conaffinity, pose=pose
        )
