"""Poses on the field, as HLVS team files give them.

A team file's poses are written as if the team played on the left half (x < 0);
:meth:`Pose.mirrored` gives the pose for the team on the right. Field dimensions:
:mod:`contracts.field`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass


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


def wrap_angle(angle: float) -> float:
    """``angle`` in [-pi, pi)."""
    return (angle + math.pi) % (2.0 * math.pi) - math.pi


__all__ = ["Pose", "wrap_angle"]
