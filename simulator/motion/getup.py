"""Getting up after a fall, from lying on the front or on the back (joint-space keyframes).

Front: push up on the hands (elbows bent, then straightened), pull the knees under the hips
(on all fours), sit back onto the feet with the hands pushing the torso back, raise the torso
into a deep squat, stand. Back: lift the legs and swing the arms to roll onto the front, then
the front sequence. Angles are written for kid-default's motor signs
(simulator/world/robots/geometry.py) and apply to every model of that shape.
"""

from __future__ import annotations

from simulator.motion.keyframes import Keyframe, KeyframeMotion
from simulator.motion.models import kinematics
from simulator.motion.posture import standing_posture

Frame = tuple[float, dict[str, float]]  # (duration s, {joint without side suffix: rad})

# Tuned in the MuJoCo world by a search over keyframes from perturbed lying poses. Some targets
# lie beyond the motor limits on purpose: the motors clamp them, and interpolating towards
# them makes the joint reach its limit earlier in the move, which is part of the tuned timing.
FRONT: tuple[Frame, ...] = (
    (0.16, {"Shoulder": 0.43, "ArmLower": 2.55, "ArmUpper": 0.92, "LegUpper": 0.57,
            "LegLower": -1.28, "Ankle": -0.67}),
    (0.25, {"Shoulder": 2.23, "ArmLower": 0.37, "ArmUpper": 0.18, "LegUpper": 0.03,
            "LegLower": 0.0, "Ankle": -0.75}),
    (0.32, {"Shoulder": 1.51, "ArmLower": -0.93, "ArmUpper": -1.2, "LegUpper": 2.62,
            "LegLower": 2.13, "Ankle": 1.49}),
    (0.38, {"Shoulder": 3.44, "ArmLower": 0.97, "ArmUpper": -0.22, "LegUpper": 3.27,
            "LegLower": 2.67, "Ankle": 0.71}),
    (0.1, {"Shoulder": 1.0, "ArmLower": -0.41, "ArmUpper": 0.62, "LegUpper": 1.35,
           "LegLower": 2.93, "Ankle": 1.38}),
    (0.52, {"Shoulder": 0.1, "ArmLower": -0.07, "ArmUpper": 0.34, "LegUpper": 1.45,
            "LegLower": 2.5, "Ankle": 1.15}),
)  # fmt: skip
BACK_TO_FRONT: tuple[Frame, ...] = (
    (0.5, {"Shoulder": 0.0, "ArmLower": 0.0, "ArmUpper": 0.2, "LegUpper": 0.0, "LegLower": 0.0,
           "Ankle": 0.0, "Pelv": 0.0, "PelvY": 0.0, "Foot": 0.0}),
    (0.6, {"Shoulder": -1.5, "LegUpper": 1.5}),
    (0.6, {"Shoulder": -2.5, "LegUpper": 2.1, "LegLower": 1.0}),
)  # fmt: skip
STAND_S = 1.0
MIRRORED = ("ArmUpper", "Pelv", "PelvY", "Foot")  # roll/yaw joints: opposite sign on the right


def _both_sides(joints: dict[str, float]) -> dict[str, float]:
    out: dict[str, float] = {}
    for name, value in joints.items():
        out[name + "L"] = value
        out[name + "R"] = -value if name in MIRRORED else value
    return out


class GetUpMotion(KeyframeMotion):
    """Get up from lying on ``side`` ("front" or "back"); ``start`` is the current posture."""

    def __init__(
        self, side: str, *, model: str = "kid-default", start: dict[str, float] | None = None
    ) -> None:
        if side not in ("front", "back"):
            raise ValueError(f"side must be 'front' or 'back', not {side!r}")
        self.side = side
        kin = kinematics(model)
        stand = standing_posture(model)
        script = FRONT if side == "front" else BACK_TO_FRONT + FRONT
        frames: list[Keyframe] = []
        current = dict(stand)
        current.update(kin.head_targets(0.0, 0.0))
        for duration, joints in script:
            current = dict(current)
            current.update(_both_sides(joints))
            frames.append(Keyframe(duration_s=duration, targets=current))
        frames.append(Keyframe(duration_s=STAND_S, targets=stand))
        super().__init__(frames, start=start or stand)
