"""Getting up after a fall, from lying on the front or on the back (joint-space keyframes).

One script per built-in model (:data:`SCRIPTS`), paced for its catalogue servos: no target moves
faster than its joint's no-load speed, so the servos' torque-speed line leaves torque to move
the body. Angles are written for the built-in models' motor signs (robot/geometry.py).

kid-default, front (about 10 s): arms out and forward, push up on them, jackknife into a pike on
hands and flat feet, fold the knees into a crouch on hands and feet and hold it (a statically
stable pose: every fall goes on from the same state), push off the hands onto the toes, rock
back onto the heels, lean into a squat and stand. Back (about 1.8 s): tuck the left leg, push
the ground behind the back with the left arm and swing the leg across to roll over the right
side onto the front, and lie flat; the caller (the stub controller) then sees a robot lying on
its front and runs the front get-up.

adult-default cannot move like that: scaled up twice it weighs 8 times as much, so its joints
need 16 times the kid's torque, and its Dynamixel-P servos give the legs about a third of that
and the arms about a fifth (PH54-200 44.7 N m, PH54-100 25.3 N m against the kid's 8.3 and
7.3), at 3.5 rad/s instead of 9.2. Its arms cannot push it up, nor push off from the crouch on
hands and knees, and the kid's quick push-off and rock back would outrun its servos. So its front
get-up (about 12.7 s) gets the weight onto the feet with the legs alone: the kid's first frames
into the pike (the push-up frame lifts nothing, the jackknife does the work), then the legs
straighten and lean back under the pike until the weight is on the feet and the hands come off
the ground, the knees bend with the shins upright so that the hips go back over the heels, into
a squat, and it stands. Its roll from the back (about 2.8 s, then the front get-up: about 16 s
from the start of the roll to standing) has its own frames: left leg up and turned out, right
leg back and wide, the left arm pushing the ground and the left leg swinging across. Both stay
within the referee's 20 s for a fallen robot (the fallen flag of the world's snapshot stays on
for at most about 14.3 s from the back, 10.9 s from the front).
"""

from __future__ import annotations

from dataclasses import dataclass

from robot.motion.keyframes import Keyframe, KeyframeMotion
from robot.motion.models import kinematics
from robot.motion.posture import standing_posture

Frame = tuple[float, dict[str, float]]  # (duration s, {joint without side suffix: rad})

# Tuned in the MuJoCo world (grass turf, cleated feet) with the catalogue servos by a search over
# keyframes within the servos' speed, on robots laid down and pushed over in several directions
# (both models).
# Some targets lie beyond the motor limits on purpose: the motors clamp them, and interpolating
# towards them makes the joint reach its limit earlier in the move, which is part of the tuned
# timing.
_CROUCH = {"LegUpper": 2.25, "LegLower": 2.2, "Ankle": 1.81, "Shoulder": 1.06, "ArmLower": 0.08}
FRONT: tuple[Frame, ...] = (
    (0.8, {"Shoulder": 0.0, "ArmUpper": 1.5, "ArmLower": 0.0, "LegUpper": 0.0,
           "LegLower": 0.0, "Ankle": 0.0, "Pelv": 0.0, "Foot": 0.0}),  # arms out, legs straight
    (1.0, {"Shoulder": 2.06}),  # the arms turn to point ahead
    (0.59, {"ArmUpper": 0.09}),  # ... and swing down under the chest: push-up
    (1.2, {"LegUpper": 2.4, "LegLower": -0.78, "Ankle": 0.41, "Shoulder": 3.19,
           "ArmLower": 0.14}),  # jackknife: pike on hands and flat feet
    (1.22, {"LegUpper": 1.36, "LegLower": 2.74, "Ankle": 1.15, "Shoulder": 2.85,
            "ArmLower": -0.1}),  # fold the knees
    (1.09, _CROUCH),  # crouch on hands and feet
    (0.6, _CROUCH),  # hold it: every fall goes on from here
    (0.91, {"LegUpper": 0.75, "LegLower": 3.56, "Ankle": 1.18, "Shoulder": 1.88,
            "ArmLower": 1.02}),  # push off the hands onto the toes
    (0.44, {"LegUpper": 0.54, "LegLower": 3.89, "Ankle": 0.74, "Shoulder": 1.36,
            "ArmLower": -0.2}),  # rock back ...
    (0.33, {"LegUpper": 0.35, "LegLower": 2.07, "Ankle": 1.93, "Shoulder": 0.29,
            "ArmLower": -0.29}),  # ... onto the heels
    (0.19, {"LegUpper": 1.29, "LegLower": 1.87, "Ankle": 0.8, "Shoulder": 1.15,
            "ArmLower": -0.24}),  # lean into the squat
)  # fmt: skip
BACK_TO_FRONT: tuple[Frame, ...] = (  # roll over the right side onto the front (sides differ)
    (
        0.51,  # left leg tucked, right leg back and turned in, arms apart
        {"ShoulderR": 1.48, "ArmUpperR": -0.53, "ArmLowerR": -0.1, "ShoulderL": -0.9,
         "ArmUpperL": 1.35, "ArmLowerL": 0.53, "LegUpperL": 2.2, "LegLowerL": 2.6, "PelvL": -0.17,
         "PelvYL": -0.33, "AnkleL": -1.2, "LegUpperR": -1.0, "LegLowerR": 0.33, "PelvR": -0.6,
         "PelvYR": -0.9, "AnkleR": 0.87},
    ),
    (0.2, {"ShoulderL": -1.42, "ArmUpperL": 0.72}),  # the left arm pushes the ground behind
    (
        0.33,  # ... and the left leg swings across
        {"ShoulderL": -1.52, "ArmUpperL": -0.3, "LegUpperL": 1.04, "PelvL": 0.37,
         "PelvYL": -0.9},
    ),
    (0.2, {"ShoulderL": -2.08, "ArmUpperL": -0.3, "LegUpperL": 0.63, "PelvYL": -0.9}),
)  # fmt: skip
LIE_FLAT: Frame = (
    0.6,
    {"Shoulder": 0.0, "ArmLower": 0.0, "ArmUpper": 0.2, "LegUpper": 0.0, "LegLower": 0.0,
     "Ankle": 0.0, "Pelv": 0.0, "PelvY": 0.0, "Foot": 0.0},
)  # fmt: skip
STAND_S = 1.26
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


@dataclass(frozen=True, slots=True, kw_only=True)
class GetUpScript:
    """The keyframes of one model: ``front`` ends in a squat, from which the robot stands up
    (its standing posture) in ``stand_s``; ``back_to_front`` and ``lie_flat`` roll it over."""

    front: tuple[Frame, ...]
    stand_s: float
    back_to_front: tuple[Frame, ...]
    lie_flat: Frame


KID = GetUpScript(front=FRONT, stand_s=STAND_S, back_to_front=BACK_TO_FRONT, lie_flat=LIE_FLAT)


# adult-default: the kid's first frames (arms forward, jackknife into a pike), then the legs stand
# upright under the pike and the knees bend under the hips into a squat (see the module docstring)
ADULT_FRONT: tuple[Frame, ...] = (
    (1.3, FRONT[0][1]),  # arms out, legs straight
    (1.62, FRONT[1][1]),  # the arms turn to point ahead
    (0.96, FRONT[2][1]),  # ... and swing down under the chest (they cannot lift it)
    (1.95, FRONT[3][1]),  # jackknife: pike on hands and flat feet
    (0.9, {"Shoulder": 1.5}),  # arms back towards the feet (they move once the hands are free)
    (0.3, {}),  # hold
    (0.9, {"Ankle": -0.25, "LegLower": 0.0}),  # legs upright, leaning back: weight on the feet
    (0.3, {}),  # hold: standing on the feet alone, bent over
    (0.9, {"LegUpper": 2.2, "LegLower": 0.6, "Ankle": 0.0, "Shoulder": 0.5,
           "ArmLower": 0.0}),  # knees bend, shins upright: the hips go back over the heels
    (0.9, {"LegUpper": 2.1, "LegLower": 1.4, "Ankle": 0.4}),
    (0.9, {"LegUpper": 1.55, "LegLower": 2.2, "Ankle": 1.0}),  # squat
)  # fmt: skip
ADULT_BACK_TO_FRONT: tuple[Frame, ...] = (  # roll over the right side onto the front
    (
        0.81,  # left leg up and out, right leg back, wide and turned in, arms apart
        {"AnkleL": 0.42, "AnkleR": 1.2, "ArmLowerL": 1.34, "ArmLowerR": 0.41, "ArmUpperL": 1.12,
         "ArmUpperR": -1.07, "LegLowerL": 0.6, "LegLowerR": 0.62, "LegUpperL": 2.2,
         "LegUpperR": -1.0, "PelvL": 0.6, "PelvR": -0.6, "PelvYL": 0.9, "PelvYR": -0.77,
         "ShoulderL": -0.52, "ShoulderR": 0.69},
    ),
    (0.32, {"ArmUpperL": 1.06, "ShoulderL": -1.21}),  # the left arm pushes the ground behind
    (
        0.38,  # ... and the left leg swings across
        {"ArmUpperL": 0.59, "LegUpperL": 1.63, "PelvL": 0.6, "PelvYL": 0.09, "ShoulderL": -1.66},
    ),
    (0.47, {"ArmUpperL": -0.3, "LegUpperL": 1.87, "PelvYL": -0.9, "ShoulderL": -1.24}),
)  # fmt: skip
ADULT_LIE_FLAT: Frame = (  # on the front: the front get-up's first frame sets every joint
    0.79,
    {"Ankle": 1.2, "ArmLower": -0.1, "ArmUpper": 0.98, "Foot": 0.13, "LegLower": 0.55,
     "LegUpper": 0.2, "Pelv": 0.6, "PelvY": 0.27, "Shoulder": -0.69},
)  # fmt: skip
ADULT = GetUpScript(
    front=ADULT_FRONT,
    stand_s=1.8,
    back_to_front=ADULT_BACK_TO_FRONT,
    lie_flat=ADULT_LIE_FLAT,
)
SCRIPTS: dict[str, GetUpScript] = {"kid-default": KID, "adult-default": ADULT}


class GetUpMotion(KeyframeMotion):
    """Get up from lying on ``side`` ("front" or "back"); ``start`` is the current posture."""

    def __init__(
        self, side: str, *, model: str = "kid-default", start: dict[str, float] | None = None
    ) -> None:
        if side not in ("front", "back"):
            raise ValueError(f"side must be 'front' or 'back', not {side!r}")
        self.side = side
        kin = kinematics(model)  # unknown models raise UnknownModelError
        script = SCRIPTS[model]
        stand = standing_posture(model)
        frames: list[Keyframe] = []
        current = dict(stand)
        current.update(kin.head_targets(0.0, 0.0))
        frames_of_side = (
            script.front if side == "front" else (*script.back_to_front, script.lie_flat)
        )
        for duration, joints in frames_of_side:
            current = dict(current)
            current.update(_both_sides(joints))
            frames.append(Keyframe(duration_s=duration, targets=current))
        if side == "front":
            frames.append(Keyframe(duration_s=script.stand_s, targets=stand))
        super().__init__(frames, start=start or stand)
