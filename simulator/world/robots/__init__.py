"""Registry of the robot models: the built-in ones (``kid-default``, ``adult-default``) and team
model packages, named by their folder's path (see :mod:`simulator.world.robots.team`)."""

from __future__ import annotations

from pathlib import Path

from robot.errors import UnknownModelError
from robot.geometry import (
    ADULT_GEOMETRY,
    ADULT_SCALE,
    KID_GEOMETRY,
    MOTOR_NAMES,
    HumanoidGeometry,
    motor_range,
)
from simulator.world.robots.model import (
    FORCE_SENSORS,
    CameraSpec,
    MotorSpec,
    RobotMjcf,
    RobotModel,
)
from simulator.world.robots.team import TeamRobotModel, load_team_model

AnyRobotModel = RobotModel | TeamRobotModel

# kp N m/rad, max torque N m, max velocity rad/s for the kid model (ranges: robot.geometry).
# Stiff, damped servos (kv = KV_TIME_S * kp): with the softer kp / 2 and no damping the
# open-loop gait of robot.motion drifts and falls within seconds.
_KID_MOTORS: dict[str, tuple[float, float, float]] = {
    "Neck": (16.0, 6.0, 6.0),
    "Head": (16.0, 6.0, 6.0),
    "Shoulder": (40.0, 6.0, 6.0),
    "ArmUpper": (40.0, 6.0, 6.0),
    "ArmLower": (30.0, 6.0, 6.0),
    "PelvY": (80.0, 8.0, 6.0),
    "Pelv": (160.0, 10.0, 6.0),
    "LegUpper": (160.0, 10.0, 6.0),
    "LegLower": (160.0, 10.0, 6.0),
    "Ankle": (160.0, 10.0, 6.0),
    "Foot": (160.0, 10.0, 6.0),
}
KV_TIME_S = 0.005


def _motors(scale: float) -> tuple[MotorSpec, ...]:
    torque_scale = scale**4  # torque ~ mass x length ~ scale^4
    motors = []
    for name in MOTOR_NAMES:
        kp, torque, velocity = _KID_MOTORS[name if name in _KID_MOTORS else name[:-1]]
        lower, upper = motor_range(name)
        motors.append(
            MotorSpec(
                name=name,
                lower_rad=lower,
                upper_rad=upper,
                kp_nm_per_rad=kp * torque_scale,
                kv_nm_s_per_rad=kp * torque_scale * KV_TIME_S * scale**0.5,
                max_torque_nm=torque * torque_scale,
                max_velocity_rad_s=velocity / scale**0.5,
            )
        )
    return tuple(motors)


KID_DEFAULT = RobotModel(
    name="kid-default",
    field_class="kid",
    geometry=KID_GEOMETRY,
    motors=_motors(1.0),
    joint_damping=0.3,
    joint_armature=0.01,
)
ADULT_DEFAULT = RobotModel(
    name="adult-default",
    field_class="adult",
    geometry=ADULT_GEOMETRY,
    motors=_motors(ADULT_SCALE),
    joint_damping=0.3 * ADULT_SCALE**4,
    joint_armature=0.01 * ADULT_SCALE**5,
)

_MODELS = {model.name: model for model in (KID_DEFAULT, ADULT_DEFAULT)}


def known_models() -> tuple[str, ...]:
    """Names of the built-in robot models, sorted."""
    return tuple(sorted(_MODELS))


def is_model_path(name: str) -> bool:
    """True when ``name`` names a model package folder rather than a built-in model."""
    return "/" in name or name.startswith(".")


def robot_model(name: str) -> AnyRobotModel:
    """The built-in model called ``name``, or the team model package at the path ``name``.

    Unknown built-in names raise :class:`UnknownModelError` (listing the known ones); a package
    that cannot be used raises :class:`simulator.errors.ModelError` with every problem."""
    if is_model_path(name):
        return load_team_model(Path(name))
    try:
        return _MODELS[name]
    except KeyError:
        raise UnknownModelError(name=name, known=list(_MODELS)) from None


__all__ = [
    "ADULT_DEFAULT",
    "AnyRobotModel",
    "FORCE_SENSORS",
    "KID_DEFAULT",
    "MOTOR_NAMES",
    "CameraSpec",
    "HumanoidGeometry",
    "MotorSpec",
    "RobotMjcf",
    "RobotModel",
    "TeamRobotModel",
    "is_model_path",
    "known_models",
    "robot_model",
]
