"""Getting up after a fall, from lying on the front or on the back (joint-space keyframes).

Front: push up on the hands, throw the legs under the body and the arms up into a deep squat,
stand. Back: swing the legs and arms across to roll onto the front and lie flat; the caller
(the stub controller) then sees a robot lying on its front and runs the front get-up. Angles
are written for kid-default's motor signs (robot/geometry.py).
"""

from __future__ import annotations

from robot.motion.keyframes import Keyframe, KeyframeMotion
from robot.motion.models import kinematics
from robot.motion.posture import standing_posture

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
BACK_TO_FRONT: tuple[Frame, ...] = (  # roll over onto the front (sides differ)
    (
        1.35,
        {"ShoulderL": 1.38, "ShoulderR": 1.82, "ArmUpperL": -0.15, "ArmUpperR": 1.15,
        "ArmLowerL": -0.04, "ArmLowerR": 0.0, "LegUpperL": 1.5, "LegUpperR": 2.39, "LegLowerL":
        0.31, "LegLowerR": 0.93, "PelvL": -1.03, "PelvR": 0.25, "PelvYL": 0.0, "PelvYR": 0.82},
    ),
    (
        0.2,
        {"ShoulderL": 1.5, "ShoulderR": 1.58, "ArmUpperL": -0.3, "ArmUpperR": -2.5, "ArmLowerL":
        1.1, "ArmLowerR": 0.0, "LegUpperL": 2.22, "LegUpperR": 1.5, "LegLowerL": 1.24,
        "LegLowerR": 0.12, "PelvL": -0.55, "PelvR": -0.34, "PelvYL": 1.02, "PelvYR": 0.09},
    ),
    (
        1.21,
        {"ShoulderL": 0.84, "ShoulderR": 0.94, "ArmUpperL": 0.85, "ArmUpperR": -2.98,
        "ArmLowerL": -0.53, "ArmLowerR": 0.0, "LegUpperL": 0.5, "LegUpperR": 0.5, "LegLowerL":
        0.3, "LegLowerR": 0.15, "PelvL": 0.54, "PelvR": -1.82, "PelvYL": 0.93, "PelvYR": -0.5},
    ),
    (
        0.36,
        {"ShoulderL": 1.53, "ShoulderR": -0.39, "ArmUpperL": 0.56, "ArmUpperR": 1.28,
        "ArmLowerL": 0.45, "ArmLowerR": 0.0, "LegUpperL": -1.26, "LegUpperR": -1.13,
        "LegLowerL": -1.23, "LegLowerR": -0.13, "PelvL": 0.0, "PelvR": 0.0, "PelvYL": -0.17,
        "PelvYR": 0.36},
    ),
)  # fmt: skip
LIE_FLAT: Frame = (
    0.6,
    {"Shoulder": 0.0, "ArmLower": 0.0, "ArmUpper": 0.2, "LegUpper": 0.0, "LegLower": 0.0,
     "Ankle": 0.0, "Pelv": 0.0, "PelvY": 0.0, "Foot": 0.0},
)  # fmt: skip
STAND_S = 1.0
MIRRORED = ("ArmUpper", "Pelv", "PelvY", "Foot")  # roll/yaw joints: opposite sign on the right


def _both_sides(joints: dict[str, float]) -> dict[str, float]:
    """Expand joint names without a side to both sides; full motor names stay as they are."""
    out: dict[str, float] = {}
    for name, value in joints.items():
        if name.endswith(("L", "R")) and name not in ("ArmUpper",):
            out[name] = value
            continue
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
        frames: list[Keyframe] = []
        current = dict(stand)
        current.update(kin.head_targets(0.0, 0.0))
        script = FRONT if side == "front" else (*BACK_TO_FRONT, LIE_FLAT)
        for duration, joints in script:
            current = dict(current)
            current.update(_both_sides(joints))
            frames.append(Keyframe(duration_s=duration, targets=current))
        if side == "front":
            frames.append(Keyframe(duration_s=STAND_S, targets=stand))
        super().__init__(frames, start=start or stand)
