"""Plain types of the world API: robot placements, device kinds, naming helpers."""

from __future__ import annotations

from dataclasses import dataclass
from enum import StrEnum
from typing import Literal

from contracts import RobotId, TeamColor

FieldClassName = Literal["kid", "adult"]
DivergencePolicy = Literal["fail", "reset_robot"]


class DeviceKind(StrEnum):
    """Kinds of robot devices the robot API exposes (HLVS / Webots device types)."""

    MOTOR = "motor"
    POSITION_SENSOR = "position_sensor"
    ACCELEROMETER = "accelerometer"
    GYRO = "gyro"
    CAMERA = "camera"
    FORCE = "force"


@dataclass(frozen=True, slots=True, kw_only=True)
class RobotPlacement:
    """A robot to put into the world: its id, built-in model name and pose in the world frame.

    The pose is already mirrored for the side the team plays on (see ``World.from_spec``).
    """

    id: RobotId
    model: str
    x_m: float
    y_m: float
    yaw_rad: float


def robot_prefix(robot: RobotId) -> str:
    """MJCF name prefix of a robot: ``red_1``; its joints are ``red_1/Neck`` and so on."""
    return f"{robot.team.value}_{robot.number}"


def parse_prefix(prefix: str) -> RobotId:
    """Inverse of :func:`robot_prefix`."""
    team, _, number = prefix.partition("_")
    return RobotId(TeamColor(team), int(number))
