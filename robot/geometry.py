"""Kinematic and inertial description of our humanoid models (one shape, scaled per class).

The one source of the built-in robots' dimensions: the simulator builds their MJCF from it
(``simulator.world.robots``) and the robot-side motion code (:mod:`robot.motion.models`) derives
its kinematics from it; ``tests/unit/stub/test_robot_geometry.py`` checks both against the
compiled MuJoCo model. Standard library only.

Robot frame: x forward, y left, z up; origin of the root body ``<robot>/torso`` is the pelvis
centre. All three hip joints (``PelvY``, ``Pelv``, ``LegUpper``) intersect at the hip point and
both ankle joints (``Ankle``, ``Foot``) at the ankle point, so leg inverse kinematics reduces to a
planar two-link problem (thigh, shank) plus yaw and roll.

Kid-default link lengths (metres; adult-default multiplies every length by ``ADULT_SCALE``)::

    hip point          (0, +-0.055, -0.03) from the pelvis centre
    thigh              0.16  hip point -> knee
    shank              0.16  knee -> ankle point
    ankle height       0.045 ankle point -> sole
    foot               0.17 long x 0.09 wide x 0.02 high, centre 0.01 forward of the ankle: a
                       plate 0.008 thick on four cleats (spheres r 0.006, one in each corner)
    standing height    pelvis centre 0.395 above the ground with every motor at zero
    shoulder           (0, +-0.115, 0.17); upper arm 0.11, forearm 0.11 (hand at its end)
    neck               (0, 0, 0.21); head sphere r 0.06, camera 0.0552 forward of its centre

Joint signs (same for left and right, all with the robot standing straight at zero):

    PelvY*   (hip yaw, axis +z)      positive turns the leg's toes to the left
    Pelv*    (hip roll, axis +x)     positive moves the foot to the left
    LegUpper (hip pitch, axis -y)    positive swings the thigh forward
    LegLower (knee, axis +y)         positive bends the knee (shank backwards)
    Ankle    (ankle pitch, axis -y)  positive lifts the toes
    Foot     (ankle roll, axis +x)   positive tilts the sole's left edge up
    Shoulder (axis -y)               positive swings the arm forward
    ArmUpper (axis +x)               positive moves the arm to the left
    ArmLower (elbow, axis -y)        positive bends the forearm forward
    Neck     (axis +z)               positive looks left
    Head     (axis +y)               positive looks down

A crouch keeping the torso upright and the feet flat is ``LegUpper = q, LegLower = 2 q,
Ankle = q``; in general the foot stays parallel to the torso when
``Ankle = LegLower - LegUpper``.
"""

from __future__ import annotations

from dataclasses import dataclass

ADULT_SCALE = 2.0
CAMERA_FORWARD_RATIO = 0.92  # camera distance in front of the head centre, in head radii
CAMERA_FOV_RAD = 1.04  # horizontal field of view of the head camera

# (lower, upper) rad of each motor, the same for every scale; "Shoulder" stands for ShoulderL and
# ShoulderR (a name without an L/R suffix here applies to both sides).
MOTOR_RANGES: dict[str, tuple[float, float]] = {
    "Neck": (-2.0, 2.0),
    "Head": (-0.8, 1.2),
    "Shoulder": (-3.1, 3.1),
    "ArmUpperL": (-0.3, 2.8),
    "ArmUpperR": (-2.8, 0.3),
    "ArmLower": (-0.1, 2.6),
    "PelvY": (-0.9, 0.9),
    "Pelv": (-0.6, 0.6),
    "LegUpper": (-1.0, 2.2),
    "LegLower": (-0.05, 2.6),
    "Ankle": (-1.2, 1.2),
    "Foot": (-0.6, 0.6),
}

MOTOR_NAMES = (
    "Neck", "Head", "ShoulderL", "ArmUpperL", "ArmLowerL", "PelvYL", "PelvL", "LegUpperL",
    "LegLowerL", "AnkleL", "FootL", "PelvYR", "PelvR", "LegUpperR", "LegLowerR", "AnkleR", "FootR",
    "ShoulderR", "ArmUpperR", "ArmLowerR",
)  # fmt: skip


def motor_range(name: str) -> tuple[float, float]:
    """(lower, upper) rad of motor ``name`` (one of :data:`MOTOR_NAMES`)."""
    return MOTOR_RANGES[name] if name in MOTOR_RANGES else MOTOR_RANGES[name[:-1]]


@dataclass(frozen=True, slots=True, kw_only=True)
class HumanoidGeometry:
    hip_y_m: float = 0.055
    hip_z_m: float = -0.03
    thigh_m: float = 0.16
    shank_m: float = 0.16
    ankle_height_m: float = 0.045
    foot_half_length_m: float = 0.085
    foot_half_width_m: float = 0.045
    foot_half_thickness_m: float = 0.01
    foot_forward_m: float = 0.01
    cleat_radius_m: float = 0.006  # four spherical cleats under each sole, 2 radii high
    torso_half_size_m: tuple[float, float, float] = (0.055, 0.085, 0.105)
    torso_centre_z_m: float = 0.1
    shoulder_y_m: float = 0.115
    shoulder_z_m: float = 0.17
    upper_arm_m: float = 0.11
    forearm_m: float = 0.11
    neck_z_m: float = 0.21
    head_radius_m: float = 0.06
    head_centre_z_m: float = 0.07
    # masses (kg)
    torso_kg: float = 2.0
    head_kg: float = 0.35
    thigh_kg: float = 0.35
    shank_kg: float = 0.25
    foot_kg: float = 0.2
    joint_link_kg: float = 0.05
    upper_arm_kg: float = 0.12
    forearm_kg: float = 0.12

    @property
    def standing_height_m(self) -> float:
        """Height of the pelvis centre above the ground with every motor at zero."""
        return -self.hip_z_m + self.thigh_m + self.shank_m + self.ankle_height_m

    @property
    def camera_forward_m(self) -> float:
        """Distance of the head camera in front of the head centre."""
        return self.head_radius_m * CAMERA_FORWARD_RATIO

    @property
    def total_height_m(self) -> float:
        return self.standing_height_m + self.neck_z_m + self.head_centre_z_m + self.head_radius_m

    @property
    def total_mass_kg(self) -> float:
        legs = 2 * (self.thigh_kg + self.shank_kg + self.foot_kg + 3 * self.joint_link_kg)
        arms = 2 * (self.upper_arm_kg + self.forearm_kg + self.joint_link_kg)
        return self.torso_kg + self.head_kg + self.joint_link_kg + legs + arms

    def scaled(self, factor: float) -> HumanoidGeometry:
        """Every length times ``factor``, every mass times ``factor**3``."""
        values: dict[str, object] = {}
        for name in self.__dataclass_fields__:
            value = getattr(self, name)
            if name.endswith("_kg"):
                values[name] = value * factor**3
            elif isinstance(value, tuple):
                values[name] = tuple(v * factor for v in value)
            else:
                values[name] = value * factor
        return HumanoidGeometry(**values)  # type: ignore[arg-type]


KID_GEOMETRY = HumanoidGeometry()
ADULT_GEOMETRY = KID_GEOMETRY.scaled(ADULT_SCALE)
