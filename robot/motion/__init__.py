"""Motion for the built-in robots: walking, kicking, getting up, standing (numpy-free, no MuJoCo).

Everything here returns motor targets (``{motor name: rad}``) for the HLVS motor names of the
built-in models, so it runs unchanged in the stub robot container and in-process with the world.
"""

from __future__ import annotations

from robot.motion.getup import GetUpMotion
from robot.motion.imu import Attitude, AttitudeFilter, accel_attitude
from robot.motion.keyframes import Keyframe, KeyframeMotion
from robot.motion.kick import KickMotion
from robot.motion.models import RobotKinematics, kinematics, known_models
from robot.motion.posture import standing_posture
from robot.motion.servo import SERVO_PID
from robot.motion.walk import WalkEngine, WalkParams, default_walk_params

__all__ = [
    "SERVO_PID",
    "Attitude",
    "AttitudeFilter",
    "GetUpMotion",
    "Keyframe",
    "KeyframeMotion",
    "KickMotion",
    "RobotKinematics",
    "WalkEngine",
    "WalkParams",
    "accel_attitude",
    "default_walk_params",
    "kinematics",
    "known_models",
    "standing_posture",
]
