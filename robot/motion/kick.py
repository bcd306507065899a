"""A forward kick with either foot: weight shift, wind-up, swing, recover (keyframes via IK).

Positions are sole targets relative to each hip in the torso frame; lengths scale with the model.
Times are in seconds and were tuned in the MuJoCo world on kid-default.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

from robot.motion.ik import FootTarget
from robot.motion.keyframes import Keyframe, KeyframeMotion, body_pose
from robot.motion.models import ArmPose, kinematics
from robot.motion.walk import default_walk_params


@dataclass(frozen=True, slots=True, kw_only=True)
class KickParams:
    shift_m: float = 0.07  # torso over the support foot
    lift_m: float = 0.07
    windup_x_m: float = -0.07
    strike_x_m: float = 0.18
    strike_lift_m: float = 0.035
    shift_s: float = 0.6
    lift_s: float = 0.3
    windup_s: float = 0.25
    strike_s: float = 0.12
    recover_s: float = 0.35
    down_s: float = 0.35
    unshift_s: float = 0.5
    support_roll_rad: float = 0.05  # extra outward roll of the support hip
    lean_rad: float = 0.0  # more forward lean than the standing posture's, until the unshift


class KickMotion(KeyframeMotion):
    """Kick with ``foot`` ("left" or "right"); ``start`` is the posture in force (default:
    standing). The ball should be about one foot length in front of the kicking foot."""

    def __init__(
        self,
        *,
        foot: str = "right",
        model: str = "kid-default",
        start: dict[str, float] | None = None,
        params: KickParams | None = None,
    ) -> None:
        if foot not in ("left", "right"):
            raise ValueError(f"foot must be 'left' or 'right', not {foot!r}")
        self.foot = foot
        kin = kinematics(model)
        walk = default_walk_params(model)
        k = params or replace(KickParams(), **kin.kick_overrides)
        scale = kin.leg.thigh_m / 0.16
        sign = 1.0 if foot == "right" else -1.0  # torso moves towards +y for a right kick
        z = -walk.hip_height_m
        x0, y0 = walk.foot_x_offset_m, walk.foot_y_offset_m
        shift = sign * k.shift_m * scale
        arms = ArmPose(shoulder_pitch=0.0, shoulder_roll=0.35, elbow=-0.3)

        def pose(kick: tuple[float, float, float], support_roll: float) -> dict[str, float]:
            kx, kz, ky = kick
            support = FootTarget(x0, sign * y0 - shift, z)
            kicking = FootTarget(x0 + kx * scale, -sign * y0 - shift + ky, z + kz * scale)
            left, right = (support, kicking) if foot == "right" else (kicking, support)
            targets = body_pose(
                kin,
                left=left,
                right=right,
                torso_pitch_rad=walk.torso_pitch_rad + k.lean_rad,
                arms=arms,
            )
            support_motor = (kin.left_leg if foot == "right" else kin.right_leg).motors["hip_roll"]
            targets[support_motor] += sign * support_roll
            return kin.clamp(targets)

        roll = k.support_roll_rad
        frames = [
            Keyframe(duration_s=k.shift_s, targets=pose((0.0, 0.0, 0.0), roll)),
            Keyframe(duration_s=k.lift_s, targets=pose((0.0, k.lift_m, 0.0), roll)),
            Keyframe(duration_s=k.windup_s, targets=pose((k.windup_x_m, k.lift_m, 0.0), roll)),
            Keyframe(
                duration_s=k.strike_s, targets=pose((k.strike_x_m, k.strike_lift_m, 0.0), roll)
            ),
            Keyframe(duration_s=k.recover_s, targets=pose((0.0, k.lift_m, 0.0), roll)),
            Keyframe(duration_s=k.down_s, targets=pose((0.0, 0.0, 0.0), roll)),
            Keyframe(duration_s=k.unshift_s, targets=standing_targets(model)),
        ]
        super().__init__(frames, start=start or standing_targets(model))


def standing_targets(model: str) -> dict[str, float]:
    from robot.motion.posture import standing_posture

    return standing_posture(model)
