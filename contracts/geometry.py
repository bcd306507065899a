"""Poses on the field, as HLVS team files give them.

A team file's poses are written as if the team played on the left half (x < 0);
:meth:`Pose.mirrored` gives the pose for the team on the right. Field dimensions:
:mod:`contracts.field`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass


@dataclass(frozen=True, slots=True, kw_only=True)
class StartingPose:
    """A pose as HLVS team files write it: translation [x, y, z] in m and axis-angle rotation
    [ax, ay, az, angle]."""

    translation: tuple[float, float, float]
    rotation: tuple[float, float, float, float]

    @property
    def x_m(self) -> float:
        return self.translation[0]

    @property
    def y_m(self) -> float:
        return self.translation[1]

    @property
    def z_m(self) -> float:
        return self.translation[2]

    @property
    def yaw_rad(self) -> float:
        """Heading of the robot's x axis in the ground plane (angle * sign(az) for a z axis)."""
        ax, ay, az, angle = self.rotation
        norm = math.sqrt(ax * ax + ay * ay + az * az)
        if norm == 0.0:
            return 0.0
        ux, uy, uz = ax / norm, ay / norm, az / norm
        c, s = math.cos(angle), math.sin(angle)
        r00 = c + ux * ux * (1 - c)
        r10 = uy * ux * (1 - c) + uz * s
        return math.atan2(r10, r00)

    @property
    def pose(self) -> Pose:
        """The pose on the ground (height and tilt left to the world)."""
        return Pose(x_m=self.x_m, y_m=self.y_m, yaw_rad=self.yaw_rad)


@dataclass(frozen=True, slots=True, kw_only=True)
class Pose:
    """A pose on the ground: torso x, y (z chosen by the world), heading."""

    x_m: float
    y_m: float
    yaw_rad: float

    def mirrored(self) -> Pose:
        """The pose for the team playing on the right (x > 0): HLVS ``flip_pose``, a reflection
        across the centre line (x -> -x, heading -> pi - heading, wrapped to [-pi, pi))."""
        return Pose(x_m=-self.x_m, y_m=self.y_m, yaw_rad=wrap_angle(math.pi - self.yaw_rad))

    def on_side(self, *, left: bool) -> Pose:
        """This pose (written for the left half) for a team on the left or the right half."""
        return self if left else self.mirrored()

    def to_relative(self, x_m: float, y_m: float) -> tuple[float, float]:
        """A field point in the robot frame (x forward, y left) of a robot at this pose."""
        dx, dy = x_m - self.x_m, y_m - self.y_m
        c, s = math.cos(self.yaw_rad), math.sin(self.yaw_rad)
        return c * dx + s * dy, -s * dx + c * dy

    def to_field(self, x_m: float, y_m: float) -> tuple[float, float]:
        """A point in the robot frame of a robot at this pose, on the field."""
        c, s = math.cos(self.yaw_rad), math.sin(self.yaw_rad)
        return self.x_m + c * x_m - s * y_m, self.y_m + s * x_m + c * y_m


def wrap_angle(angle: float) -> float:
    """``angle`` in [-pi, pi)."""
    return (angle + math.pi) % (2.0 * math.pi) - math.pi


__all__ = ["Pose", "StartingPose", "wrap_angle"]
