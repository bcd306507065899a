"""Keyframe motions: a list of whole-body postures reached one after the other.

Each keyframe gives the motor targets to reach and the time to get there; targets are
interpolated with a cosine ease from the posture in force when the motion started (so a motion
can start from any pose). Postures are built from foot positions (through the leg IK) or from
canonical joint angles, so the same script fits every built-in model.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from robot.motion.ik import FootTarget, leg_ik
from robot.motion.models import ArmPose, RobotKinematics, arm_canonical


@dataclass(frozen=True, slots=True, kw_only=True)
class Keyframe:
    duration_s: float  # time to move from the previous keyframe to this one
    targets: dict[str, float]  # motor name -> rad


def body_pose(
    kin: RobotKinematics,
    *,
    left: FootTarget | dict[str, float],
    right: FootTarget | dict[str, float],
    torso_pitch_rad: float = 0.0,
    arms: ArmPose | tuple[ArmPose, ArmPose] | None = None,
    head_pitch_down_rad: float = 0.0,
) -> dict[str, float]:
    """Motor targets of a whole-body posture.

    ``left``/``right``: a sole position relative to its hip (solved by IK, then leaned forward
    by ``torso_pitch_rad``) or canonical leg angles used as given.
    """
    out: dict[str, float] = {}
    for leg_target, joint_map in ((left, kin.left_leg), (right, kin.right_leg)):
        if isinstance(leg_target, FootTarget):
            angles = leg_ik(kin.leg, leg_target)
            angles["hip_pitch"] -= torso_pitch_rad
        else:
            angles = dict(leg_target)
        out.update(joint_map.to_motor(angles))
    left_arm, right_arm = _arm_pair(kin, arms)
    out.update(kin.left_arm.to_motor(arm_canonical(left_arm, side="left")))
    out.update(kin.right_arm.to_motor(arm_canonical(right_arm, side="right")))
    out.update(kin.head_targets(0.0, head_pitch_down_rad))
    return kin.clamp(out)


def _arm_pair(
    kin: RobotKinematics, arms: ArmPose | tuple[ArmPose, ArmPose] | None
) -> tuple[ArmPose, ArmPose]:
    if arms is None:
        return kin.arm_rest, kin.arm_rest
    if isinstance(arms, ArmPose):
        return arms, arms
    return arms


class KeyframeMotion:
    """Plays keyframes over time: call :meth:`step` every control tick until :attr:`done`."""

    def __init__(self, keyframes: list[Keyframe], *, start: dict[str, float]) -> None:
        if not keyframes:
            raise ValueError("a keyframe motion needs at least one keyframe")
        self._frames = keyframes
        self._start = dict(start)
        self._t = 0.0
        self.duration_s = sum(frame.duration_s for frame in keyframes)

    @property
    def done(self) -> bool:
        return self._t >= self.duration_s

    @property
    def elapsed_s(self) -> float:
        return self._t

    def step(self, dt_s: float) -> dict[str, float]:
        self._t = min(self._t + dt_s, self.duration_s)
        return self.sample(self._t)

    def sample(self, t_s: float) -> dict[str, float]:
        """Targets at ``t_s`` seconds after the start."""
        previous = self._start
        elapsed = 0.0
        for frame in self._frames:
            if t_s <= elapsed + frame.duration_s or frame is self._frames[-1]:
                span = max(frame.duration_s, 1e-9)
                s = min(max((t_s - elapsed) / span, 0.0), 1.0)
                ease = 0.5 - 0.5 * math.cos(math.pi * s)
                out = dict(previous)
                for name, goal in frame.targets.items():
                    begin = previous.get(name, goal)
                    out[name] = begin + (goal - begin) * ease
                return out
            merged = dict(previous)
            merged.update(frame.targets)
            previous = merged
            elapsed += frame.duration_s
        return dict(previous)
