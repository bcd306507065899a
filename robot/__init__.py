"""The robot side of hlvs-runner: what a team's robot program uses to play a match.

``robot.client`` (the robot API and GameController client library), ``robot.motion`` (walking,
kicking, getting up for the built-in models), ``robot.stub`` (the stub robot controller) and
``robot.geometry`` (the built-in humanoids' dimensions, from which the simulator builds their
MJCF). Nothing here imports MuJoCo, the simulator server or the referee: the package installs on
its own with numpy and protobuf (see ``robot/pyproject.toml``).
"""

from typing import TYPE_CHECKING

from contracts import lazy_exports

if TYPE_CHECKING:
    from robot.errors import UnknownModelError
    from robot.geometry import (
        ADULT_GEOMETRY,
        ADULT_SCALE,
        CAMERA_FOV_RAD,
        KID_GEOMETRY,
        MOTOR_NAMES,
        HumanoidGeometry,
        motor_range,
    )

__all__ = [
    "ADULT_GEOMETRY",
    "ADULT_SCALE",
    "CAMERA_FOV_RAD",
    "HumanoidGeometry",
    "KID_GEOMETRY",
    "MOTOR_NAMES",
    "UnknownModelError",
    "motor_range",
]


if not TYPE_CHECKING:
    __getattr__, __dir__ = lazy_exports(__name__, {
        "robot.errors": ("UnknownModelError",),
        "robot.geometry": (
            "ADULT_GEOMETRY", "ADULT_SCALE", "CAMERA_FOV_RAD", "KID_GEOMETRY", "MOTOR_NAMES",
            "HumanoidGeometry", "motor_range",
        ),
    })
