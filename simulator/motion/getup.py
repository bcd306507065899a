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

FRONT: tuple[Frame, ...] = (
    (0.6, {"Shoulder": 0.8, "ArmLower": 2.3, "ArmUpper": 0.3, "LegUpper": 0.0, "LegLower": 0.0,
           "Ankle": 0.0, "Pelv": 0.0, "PelvY": 0.0, "Foot": 0.0}),
    (0.8, {"Shoulder": 1.5, "ArmLower": 0.0}),
    (0.8, {"LegUpper": 1.6, "LegLower": 2.0, "Ankle": 0.5}),
    (1.0, {"Shoulder": 2.3, "LegUpper": 2.2, "LegLower": 2.5, "Ankle": 1.0}),
    (0.8, {"Shoulder": 2.9, "Ankle": 1.2}),
    (1.2, {"LegUpper": 1.6, "Shoulder": 1.2}),
    (1.0, {"LegUpper": 1.3, "LegLower": 2.5, "Ankle": 1.15, "Shoulder": 0.5}),
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
            frames.append(Keyframe(duration_s=duration, targets=kin.clamp(current)))
        frames.append(Keyframe(duration_s=STAND_S, targets=stand))
        super().__init__(frames, start=start or stand)
