"""Analytic inverse kinematics of a 6-joint humanoid leg (hip yaw-roll-pitch, knee, ankle
pitch-roll).

Angles are canonical (see :mod:`robot.motion.models`): right-hand rotations about the torso
axes. The sole stays parallel to the torso's xy plane and turned by the requested yaw.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from robot.motion.models import LegGeometry


@dataclass(frozen=True, slots=True)
class FootTarget:
    """Sole centre relative to the hip joint, in the torso frame (metres), and its yaw (rad)."""

    x_m: float
    y_m: float
    z_m: float  # negative: the foot is below the hip
    yaw_rad: float = 0.0


def leg_ik(leg: LegGeometry, target: FootTarget) -> dict[str, float]:
    """Joint angles that put the sole at ``target``; unreachable targets are pulled in.

    Returns canonical angles keyed by :data:`robot.motion.models.LEG_JOINTS`.
    """
    cos_yaw, sin_yaw = math.cos(target.yaw_rad), math.sin(target.yaw_rad)
    # ankle joint position, then expressed in the frame after the hip yaw
    ax, ay, az = target.x_m, target.y_m, target.z_m + leg.ankle_height_m
    px = cos_yaw * ax + sin_yaw * ay
    py = -sin_yaw * ax + cos_yaw * ay
    pz = az
    hip_roll = math.atan2(py, -pz)
    depth = math.hypot(py, pz)
    a, b = leg.thigh_m, leg.shank_m
    reach = math.hypot(px, depth)
    max_reach = (a + b) * 0.9999
    if reach > max_reach:
        scale = max_reach / reach
        px, depth, reach = px * scale, depth * scale, max_reach
    reach = max(reach, abs(a - b) + 1e-6)
    cos_knee_inner = (a * a + b * b - reach * reach) / (2.0 * a * b)
    knee_flex = math.pi - math.acos(_clip(cos_knee_inner))
    cos_beta = (a * a + reach * reach - b * b) / (2.0 * a * reach)
    beta = math.acos(_clip(cos_beta))
    alpha = math.atan2(px, depth)  # forward angle of the hip-ankle line from straight down
    hip_flex = alpha + beta  # forward swing of the thigh
    # right-hand rotations about +y: forward swing of a downward segment is negative
    hip_pitch = -hip_flex
    knee = knee_flex
    ankle_pitch = -(hip_pitch + knee)
    return {
        "hip_yaw": target.yaw_rad,
        "hip_roll": hip_roll,
        "hip_pitch": hip_pitch,
        "knee": knee,
        "ankle_pitch": ankle_pitch,
        "ankle_roll": -hip_roll,
    }


def leg_fk(leg: LegGeometry, angles: dict[str, float]) -> FootTarget:
    """Sole position for canonical ``angles`` (the inverse of :func:`leg_ik`, used in tests)."""
    hip_pitch, knee = angles["hip_pitch"], angles["knee"]
    # in the pitch plane: x forward, z down-negative
    thigh_x = -math.sin(hip_pitch) * leg.thigh_m
    thigh_z = -math.cos(hip_pitch) * leg.thigh_m
    shank_angle = hip_pitch + knee
    x = thigh_x - math.sin(shank_angle) * leg.shank_m
    z = thigh_z - math.cos(shank_angle) * leg.shank_m
    roll = angles["hip_roll"]
    y_r = -math.sin(roll) * z
    z_r = math.cos(roll) * z
    yaw = angles["hip_yaw"]
    x_w = math.cos(yaw) * x - math.sin(yaw) * y_r
    y_w = math.sin(yaw) * x + math.cos(yaw) * y_r
    return FootTarget(x_w, y_w, z_r - leg.ankle_height_m, yaw)


def _clip(value: float) -> float:
    return min(1.0, max(-1.0, value))
