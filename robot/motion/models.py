"""Kinematic description of the built-in robot models, as the motion engines need it.

The motion code never imports MuJoCo (it also runs inside the stub robot image); each model's
lengths, motor ranges and camera mount come from :mod:`robot.geometry`, the same description the
simulator builds the model's MJCF from. Joint angles are computed
in a *canonical* convention and mapped to motor commands by :class:`JointMap`:

* torso frame: x forward, y left, z up;
* every canonical angle is a right-hand rotation about the torso axis the joint turns about in the
  zero pose (hip yaw about z, hip and ankle roll about x, hip, knee and ankle pitch about y);
* ``motor = sign * canonical + offset``.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from robot.errors import UnknownModelError
from robot.geometry import (
    ADULT_GEOMETRY,
    ADULT_SCALE,
    CAMERA_FOV_RAD,
    KID_GEOMETRY,
    MOTOR_NAMES,
    HumanoidGeometry,
    motor_range,
)

LEG_JOINTS = ("hip_yaw", "hip_roll", "hip_pitch", "knee", "ankle_pitch", "ankle_roll")
ARM_JOINTS = ("shoulder_pitch", "shoulder_roll", "elbow")


@dataclass(frozen=True, slots=True, kw_only=True)
class LegGeometry:
    """Lengths of one leg, in metres.

    ``hip_offset_y_m``: lateral distance from the torso centre line to each hip joint;
    ``thigh_m``: hip pitch axis to knee axis; ``shank_m``: knee axis to ankle axis;
    ``ankle_height_m``: ankle axis to the sole.
    """

    hip_offset_y_m: float
    thigh_m: float
    shank_m: float
    ankle_height_m: float

    @property
    def max_reach_m(self) -> float:
        return self.thigh_m + self.shank_m


@dataclass(frozen=True, slots=True, kw_only=True)
class JointMap:
    """Motor names of one side and the sign of each canonical angle."""

    motors: dict[str, str]  # canonical joint -> motor name
    signs: dict[str, float]  # canonical joint -> +1 / -1
    offsets: dict[str, float] = field(default_factory=dict)

    def to_motor(self, canonical: dict[str, float]) -> dict[str, float]:
        return {
            self.motors[name]: self.signs[name] * angle + self.offsets.get(name, 0.0)
            for name, angle in canonical.items()
            if name in self.motors
        }


@dataclass(frozen=True, slots=True, kw_only=True)
class ArmPose:
    """Canonical arm angles: shoulder pitch (+ swings the arm back), shoulder roll (+ moves the
    arm towards +y), elbow (- bends the forearm forward)."""

    shoulder_pitch: float
    shoulder_roll: float
    elbow: float


def arm_canonical(pose: ArmPose, *, side: str) -> dict[str, float]:
    """Canonical angles of one arm; ``pose`` is written for the left arm and mirrored for the
    right one (roll changes sign)."""
    mirror = 1.0 if side == "left" else -1.0
    return {
        "shoulder_pitch": pose.shoulder_pitch,
        "shoulder_roll": mirror * pose.shoulder_roll,
        "elbow": pose.elbow,
    }


@dataclass(frozen=True, slots=True, kw_only=True)
class CameraMount:
    """Where the head camera sits (metres): the neck yaw joint above the pelvis centre, the head
    pitch joint above the neck joint, the camera in front of the head pitch axis; the hip joints
    below the pelvis centre. Horizontal field of view in radians."""

    neck_height_m: float
    head_height_m: float
    camera_forward_m: float
    hip_below_pelvis_m: float
    fov_rad: float


KID_KICK_BALL_X_M = 0.165  # kid-default kicks a ball this far in front of its pelvis

@dataclass(frozen=True, slots=True, kw_only=True)
class RobotKinematics:
    name: str
    leg: LegGeometry
    left_leg: JointMap
    right_leg: JointMap
    left_arm: JointMap
    right_arm: JointMap
    neck_motor: str  # yaw, positive = look left
    head_motor: str  # pitch
    head_down_sign: float  # sign of the head motor that tilts the camera down
    motor_limits: dict[str, tuple[float, float]]
    arm_rest: ArmPose
    camera: CameraMount
    walk_overrides: dict[str, float] = field(default_factory=dict)
    # seconds to ease from straight legs (as placed by the referee) into the standing posture;
    # 0: straight into it at the servos' full speed
    rise_s: float = 0.0
    kick_overrides: dict[str, float] = field(default_factory=dict)  # KickParams fields
    # how far each ball sighting moves the believed ball (1: all the way); a tall robot's torso
    # sways by more while stepping, and the ball in its images with it
    ball_gain: float = 1.0
    # the ball's best distance in front of the pelvis for a kick (kid-default's, scaled, unless
    # the model says otherwise)
    kick_ball_x_m: float = KID_KICK_BALL_X_M

    @property
    def motor_names(self) -> tuple[str, ...]:
        names: list[str] = [self.neck_motor, self.head_motor]
        for joint_map in (self.left_arm, self.right_arm, self.left_leg, self.right_leg):
            names.extend(joint_map.motors.values())
        return tuple(names)

    def arm_targets(
        self, *, left_pitch: float = 0.0, right_pitch: float = 0.0, pose: ArmPose | None = None
    ) -> dict[str, float]:
        """Motor targets of both arms: ``pose`` (default: resting) plus a shoulder pitch swing."""
        rest = pose or self.arm_rest
        left = arm_canonical(rest, side="left")
        right = arm_canonical(rest, side="right")
        left["shoulder_pitch"] += left_pitch
        right["shoulder_pitch"] += right_pitch
        out = self.left_arm.to_motor(left)
        out.update(self.right_arm.to_motor(right))
        return out

    def head_targets(self, yaw_rad: float, pitch_down_rad: float) -> dict[str, float]:
        """Neck yaw (+ looks left) and head pitch (+ looks down), as motor targets."""
        return {self.neck_motor: yaw_rad, self.head_motor: self.head_down_sign * pitch_down_rad}

    def clamp(self, targets: dict[str, float]) -> dict[str, float]:
        out: dict[str, float] = {}
        for name, value in targets.items():
            low, high = self.motor_limits.get(name, (-3.14, 3.14))
            out[name] = min(max(value, low), high)
        return out


def _leg_map(side: str, signs: dict[str, float]) -> JointMap:
    names = {
        "hip_yaw": f"PelvY{side}",
        "hip_roll": f"Pelv{side}",
        "hip_pitch": f"LegUpper{side}",
        "knee": f"LegLower{side}",
        "ankle_pitch": f"Ankle{side}",
        "ankle_roll": f"Foot{side}",
    }
    return JointMap(motors=names, signs=signs)


def _arm_map(side: str, signs: dict[str, float]) -> JointMap:
    names = {
        "shoulder_pitch": f"Shoulder{side}",
        "shoulder_roll": f"ArmUpper{side}",
        "elbow": f"ArmLower{side}",
    }
    return JointMap(motors=names, signs=signs)


# Motor axes of the built-in humanoids (robot/geometry.py): hip pitch, ankle
# pitch, shoulder pitch and elbow turn about -y; every other joint about its + axis.
_LEG_SIGNS = {
    "hip_yaw": 1.0,
    "hip_roll": 1.0,
    "hip_pitch": -1.0,
    "knee": 1.0,
    "ankle_pitch": -1.0,
    "ankle_roll": 1.0,
}
_ARM_SIGNS = {"shoulder_pitch": -1.0, "shoulder_roll": 1.0, "elbow": -1.0}


def _humanoid(
    name: str,
    geometry: HumanoidGeometry,
    scale: float,
    *,
    rise_s: float = 0.0,
    walk_overrides: dict[str, float] | None = None,
    kick_overrides: dict[str, float] | None = None,
    ball_gain: float = 1.0,
    kick_ball_x_m: float | None = None,
) -> RobotKinematics:
    g = geometry
    return RobotKinematics(
        name=name,
        leg=LegGeometry(
            hip_offset_y_m=g.hip_y_m,
            thigh_m=g.thigh_m,
            shank_m=g.shank_m,
            ankle_height_m=g.ankle_height_m,
        ),
        left_leg=_leg_map("L", dict(_LEG_SIGNS)),
        right_leg=_leg_map("R", dict(_LEG_SIGNS)),
        left_arm=_arm_map("L", dict(_ARM_SIGNS)),
        right_arm=_arm_map("R", dict(_ARM_SIGNS)),
        neck_motor="Neck",
        head_motor="Head",
        head_down_sign=1.0,
        motor_limits={motor: motor_range(motor) for motor in MOTOR_NAMES},
        arm_rest=ArmPose(shoulder_pitch=0.0, shoulder_roll=0.15, elbow=-0.4),
        camera=CameraMount(
            neck_height_m=g.neck_z_m,
            head_height_m=g.head_centre_z_m,
            camera_forward_m=g.camera_forward_m,
            hip_below_pelvis_m=-g.hip_z_m,
            fov_rad=CAMERA_FOV_RAD,
        ),
        walk_overrides={**_scaled_walk(scale), **(walk_overrides or {})},
        rise_s=rise_s,
        kick_overrides=dict(kick_overrides or {}),
        ball_gain=ball_gain,
        kick_ball_x_m=KID_KICK_BALL_X_M * scale if kick_ball_x_m is None else kick_ball_x_m,
    )


def _scaled_walk(scale: float) -> dict[str, float]:
    """Gait tuned on kid-default in the MuJoCo world (lengths scale with the model)."""
    lengths = {
        "step_height_m": 0.03,
        "sway_m": 0.025,
        "hip_height_m": 0.30,
        "foot_x_offset_m": 0.01,
        "foot_y_offset_m": 0.02,
        "max_vx_m_s": 0.4,
        "max_vy_m_s": 0.05,
    }
    out = {key: value * scale for key, value in lengths.items()}
    out.update(
        # kid-default with its catalogue servos on the league's soft grass, 14 s straight ahead
        # from standing: 0.21 m/s commanded 0.3, 0.30 m/s commanded 0.4, no fall; a striker at
        # 0.3 reached a kick-off pass (3.4 m) with too little of a 40 s half left to shoot
        cruise_vx_m_s=0.4,
        period_s=0.7 * scale**0.5,
        double_support_ratio=0.35,
        sway_phase_lead=0.025,
        torso_pitch_rad=0.05,
        tilt_pitch_ankle_gain=-0.2,
        tilt_pitch_hip_gain=-0.1,
        # walked / commanded on kid-default with its catalogue servos and P = 30: 0.84 straight
        # ahead at 0.3 m/s (0.88 at 0.2 m/s), 0.76-0.80 at 0.3 m/s turning at up to 0.2 rad/s
        # (how a striker walks to the ball), 0.6 at 0.2 m/s turning, 0.94 sideways; the turn
        # loss fitted on the goalie's 4 m READY walk, which corrects its heading as it goes
        stride_efficiency_x=0.82,
        turn_stride_loss=0.6,
        stride_efficiency_y=0.94,
    )
    return out


def _kid_default() -> RobotKinematics:
    return _humanoid("kid-default", KID_GEOMETRY, 1.0)


def _adult_default() -> RobotKinematics:
    # its knees bent at the servos' full speed from straight legs throw it over backwards
    return _humanoid(
        "adult-default",
        ADULT_GEOMETRY,
        ADULT_SCALE,
        rise_s=1.0,
        walk_overrides=_ADULT_WALK,
        kick_overrides=_ADULT_KICK,
        ball_gain=0.3,
        kick_ball_x_m=_ADULT_KICK_BALL_X_M,
    )


# adult-default's gait, where the kid's scaled one does not do: with the kid's 0.05 rad lean
# alone it tips over backwards within 2.5 s at 0.3 m/s; leaning 0.1 rad more while stepping it
# walks straight, turning and sideways at 0.3 m/s, and 0.15 rad at 0.4 m/s (the stance keeps the
# kid's lean: the get-up ends in it). 30 s of random commands (forward at the cruise speed, with
# and without turning, turning in place, sideways, standing; a new one every 1.2 s on average):
# 0.3 m/s with 0.1 rad, 23 of 24 runs without a fall; 0.4 m/s with 0.15 rad, 22 of 24; 0.45 m/s
# with 0.1 rad 8 of 12, with 0.15 rad 9 of 12; 0.6 m/s falls within 2 s. Backwards (0.25 rad at
# 0.45 m/s: 3 of 12) and forwards, the lean has little room.
_ADULT_WALK = {
    "walk_lean_rad": 0.15,
    "max_vx_m_s": 0.3 * ADULT_SCALE,  # the kid's 0.3 m/s scaled, as before the kid's 0.4
    # the speed over distance: 4.6 m from the touch line to a kick-off spot in 12 s of a
    # scrimmage's 20 s READY (at 0.3 m/s it arrived unturned and kicked off 5-10 s late)
    "cruise_vx_m_s": 0.4,
    # walked / commanded with that lean (net displacement, 12 s from standing, less the speed-up):
    # 0.91 straight ahead at 0.4 m/s, 0.92 at 0.3 m/s, 0.95 sideways
    "stride_efficiency_x": 0.92,
    "turn_stride_loss": 0.0,
    "stride_efficiency_y": 0.95,
}
# adult-default's kick: with the kid's weight shift and outward support hip roll it stands on
# one leg tilting back and towards the kicking side, and falls over backwards after the kick
# (also without a ball); shifted a little farther, no extra roll, leaning forward like the gait.
# Lifted by the kid's 0.05 m (0.035 m at the strike), scaled, the swinging foot scraped the grass
# on its way forward (1 cm above the standing sole) and the stub's kicks rolled the ball 2.9-3.4 m
# from six striker starts (one fall). Lifted 0.07 (0.06) m with the ball 0.41 m ahead of the
# pelvis, where the foot is fastest, they roll it 3.1-4.0 m; leaning 0.14 rad, none fell (3 of 6
# fell over backwards with the 0.1 rad before).
_ADULT_KICK = {
    "lean_rad": 0.14, "shift_m": 0.08, "lift_m": 0.07, "strike_lift_m": 0.06,
    "support_roll_rad": 0.0,
}  # fmt: skip
_ADULT_KICK_BALL_X_M = 0.41


_MODELS = {"kid-default": _kid_default, "adult-default": _adult_default}


def kinematics(model: str) -> RobotKinematics:
    """The kinematic description of a built-in robot model."""
    try:
        factory = _MODELS[model]
    except KeyError:
        raise UnknownModelError(name=model, known=list(_MODELS)) from None
    return factory()


def known_models() -> tuple[str, ...]:
    return tuple(sorted(_MODELS))
