"""What the built-in and the team robot models share: their motors, camera and the MJCF
fragments they produce (the built-in humanoid: :mod:`simulator.world.robots.humanoid`; a team's
model: :mod:`simulator.world.robots.team`)."""

from __future__ import annotations

import math
from dataclasses import dataclass

from robot import CAMERA_FOV_RAD
from simulator.world.servos import Servo

FORCE_SENSORS = ("llb", "llf", "lrf", "lrb", "rlb", "rlf", "rrf", "rrb")
"""Sole corner force sensors: first letter foot (l/r), then side (l/r), then back/front."""


@dataclass(frozen=True, slots=True, kw_only=True)
class MotorSpec:
    """One motor (a hinge joint and its servo): the servo's figures at the joint, from the
    league catalogue (``servo`` names the entry) or, in friendlies, from a team's manifest
    (``servo`` empty). :mod:`simulator.world.actuator` turns it into MuJoCo."""

    name: str
    lower_rad: float
    upper_rad: float
    max_torque_nm: float  # stall torque (Webots maxTorque), N m at the output
    max_velocity_rad_s: float  # no-load speed (Webots maxVelocity)
    full_torque_speed_rad_s: float = 0.0  # the torque-speed line starts falling here
    static_friction_nm: float = 0.0
    damping_nm_s_per_rad: float = 0.0
    backlash_rad: float = 0.0
    # the position sensor's resolution (:mod:`simulator.world.sensor_noise`); free-form motors
    # get 2 pi / 4096 rad, the 4096-count encoder of the league's Dynamixel servos
    encoder_resolution_rad: float = 2.0 * math.pi / 4096.0
    servo: str = ""  # catalogue id (MX-106@14.8V); empty for free-form figures
    armature_kg_m2: float = 0.0  # the servo's reflected rotor inertia at the joint

    @classmethod
    def from_servo(cls, name: str, lower_rad: float, upper_rad: float, servo: Servo) -> MotorSpec:
        return cls(
            name=name,
            lower_rad=lower_rad,
            upper_rad=upper_rad,
            max_torque_nm=servo.stall_torque_nm,
            max_velocity_rad_s=servo.no_load_speed_rad_s,
            full_torque_speed_rad_s=servo.full_torque_speed_rad_s,
            static_friction_nm=servo.static_friction_nm,
            damping_nm_s_per_rad=servo.viscous_damping_nm_s_per_rad,
            backlash_rad=servo.backlash_rad,
            encoder_resolution_rad=servo.encoder_resolution_rad,
            servo=servo.id,
            armature_kg_m2=servo.armature_kg_m2,
        )


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
