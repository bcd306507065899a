"""Registry of the robot models: the built-in ones (``kid-default``, ``adult-default``) and team
model packages, named by their folder's path (see :mod:`simulator.world.robots.team`)."""

from __future__ import annotations

from pathlib import Path

from robot import (
    ADULT_GEOMETRY,
    ADULT_SCALE,
    KID_GEOMETRY,
    MOTOR_NAMES,
    HumanoidGeometry,
    UnknownModelError,
    motor_range,
)
from simulator.world.robots.humanoid import RobotModel
from simulator.world.robots.league import LEAGUE_TEST_KID_NAME, league_test_kid
from simulator.world.robots.model import (
    FORCE_SENSORS,
    CameraSpec,
    MotorSpec,
    RobotMjcf,
)
from simulator.world.robots.team import TeamRobotModel, load_team_model
from simulator.world.servos import servo

AnyRobotModel = RobotModel | TeamRobotModel

# Catalogue servos of the built-in models per joint group (ranges: robot.geometry): kid-size
# as the league's Dynamixel robots at 14.8 V, adult-size with Dynamixel-P servos.
_KID_SERVOS: dict[str, str] = {
    "Neck": "MX-28@14.8V",
    "Head": "MX-28@14.8V",
    "Shoulder": "MX-64@14.8V",
    "ArmUpper": "MX-64@14.8V",
    "ArmLower": "MX-64@14.8V",
    "PelvY": "MX-64@14.8V",
    "Pelv": "XW540-T140@14.8V",
    "LegUpper": "XW540-T140@14.8V",
    "LegLower": "XW540-T140@14.8V",
    "Ankle": "XW540-T140@14.8V",
    "Foot": "XW540-T140@14.8V",
}
_ADULT_SERVOS: dict[str, str] = {
    "Neck": "PH42-020-S300-R@24V",
    "Head": "PH42-020-S300-R@24V",
    "Shoulder": "PH54-100-S500-R@24V",
    "ArmUpper": "PH54-100-S500-R@24V",
    "ArmLower": "PH54-100-S500-R@24V",
    "PelvY": "PH54-100-S500-R@24V",
    "Pelv": "PH54-200-S500-R@24V",
    "LegUpper": "PH54-200-S500-R@24V",
    "LegLower": "PH54-200-S500-R@24V",
    "Ankle": "PH54-200-S500-R@24V",
    "Foot": "PH54-200-S500-R@24V",
}


def _motors(servos: dict[str, str]) -> tuple[MotorSpec, ...]:
    motors = []
    for name in MOTOR_NAMES:
        lower, upper = motor_range(name)
        entry = servo(servos[name if name in servos else name[:-1]])
        motors.append(MotorSpec.from_servo(name, lower, upper, entry))
    return tuple(motors)


KID_DEFAULT = RobotModel(
    name="kid-default",
    field_class="kid",
    geometry=KID_GEOMETRY,
    motors=_motors(_KID_SERVOS),
    joint_armature=0.01,
)
ADULT_DEFAULT = RobotModel(
    name="adult-default",
    field_class="adult",
    geometry=ADULT_GEOMETRY,
    motors=_motors(_ADULT_SERVOS),
    joint_armature=0.01 * ADULT_SCALE**5,
)

_MODELS = {model.name: model for model in (KID_DEFAULT, ADULT_DEFAULT)}
# the league's test robot (:mod:`simulator.world.robots.league`): resolved by name for the
# league's referee test scenarios, never listed among the models a team may choose
LEAGUE_TEST_KID = league_test_kid(KID_DEFAULT)
_TEST_MODELS = {LEAGUE_TEST_KID.name: LEAGUE_TEST_KID}


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
        return _MODELS[name] if name in _MODELS else _TEST_MODELS[name]
    except KeyError:
        raise UnknownModelError(name=name, known=list(_MODELS)) from None


__all__ = [
    "ADULT_DEFAULT",
    "AnyRobotModel",
    "FORCE_SENSORS",
    "KID_DEFAULT",
    "LEAGUE_TEST_KID",
    "LEAGUE_TEST_KID_NAME",
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
