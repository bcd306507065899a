"""The league's test robot, for the league's referee test scenarios only (``hlvs referee test``).

The league's referee tests play the league's sample robot, ``RobocupRobot``: a Darwin-OP
(hlvs_webots ``protos/robots/RoboCupRobot/Darwin-opHinge2Robocup.proto``) that has no controller
and so keeps the pose its proto stores: a deep crouch (``LegUpper`` 1.15, ``LegLower`` -2.25,
``Ankle`` -1.23 rad, lines 808-810, 870-872, 919-921), its origin 0.24 m above the ground (the
team files' ``halfTimeStartingPose``). Its scenarios push the ball into its legs and its legs into
each other's, so where a ball or a robot stops depends on that body. This model is our humanoid
with the Darwin-OP's dimensions taken from the proto's bounding objects and masses (2.93 kg in
all) and the same crouch:

    root            the Darwin-OP's origin (torso centre), 0.24 m above the ground standing
    hip point       (0, +-0.045, -0.122): PelvY anchors at (-0.005, +-0.037, -0.1222), line 718
    thigh, shank    0.093 each (the knee and ankle anchors, lines 871, 920); crouched at 1.126
                    rad the knees' front reaches 0.112 forward of the origin (the proto's knee
                    boxes: 0.109); boxes 0.05 deep and 0.062 wide, the shank's from 0.0165
                    above the knee (the shank's boxes, lines 1033-1050), which leave 0.028 m
                    between the legs, so that a ball pushed into the knees meets their fronts
                    (capsules of radius 0.022 took it between them and held it there)
    foot            0.105 long x 0.068 wide (box ``0.066 0.013 0.105``, line 1020)
    ankle servos    a box on the foot, 0.083 long x 0.036 wide x 0.045 high, from 0.062 behind
                    the ankle to 0.021 in front of it, 0.021 to 0.066 above the ground (the
                    foot's ``Motors`` box ``0.036 0.045 0.083`` at ``0 0.01 -0.0205``, lines
                    1006-1012): a ball rolling into the robot's heel stops against it
    torso           0.112 x 0.114 x 0.116 box (the body's boxes, 0.1 x 0.058 x 0.091 ...)
    arms            shoulders at (0, +-0.082, 0) hanging to 0.137 below it (lines 1552-1746)
    head            a sphere r 0.045 above the neck at 0.051 (capsule r 0.042, lines 436-441)

The robot is never a team's choice: the configuration's built-in models do not name it
(:data:`orchestrator.config.BUILT_IN_MODELS`) and matches never play it.
"""

from __future__ import annotations

from robot import HumanoidGeometry
from simulator.world.robots.humanoid import RobotModel

LEAGUE_TEST_KID_NAME = "league-test-kid"

LEAGUE_TEST_KID_GEOMETRY = HumanoidGeometry(
    hip_y_m=0.045,
    hip_z_m=-0.122,
    thigh_m=0.093,
    shank_m=0.093,
    ankle_height_m=0.038,
    foot_half_length_m=0.0525,
    foot_half_width_m=0.034,
    foot_half_thickness_m=0.007,
    foot_forward_m=0.0,
    cleat_radius_m=0.004,
    torso_half_size_m=(0.056, 0.057, 0.058),
    torso_centre_z_m=-0.03,
    shoulder_y_m=0.1,
    shoulder_z_m=0.0,
    upper_arm_m=0.065,
    forearm_m=0.07,
    neck_z_m=0.051,
    head_radius_m=0.045,
    head_centre_z_m=0.03,
    torso_kg=0.98,
    head_kg=0.34,
    thigh_kg=0.14,
    shank_kg=0.1,
    foot_kg=0.22,
    joint_link_kg=0.04,
    upper_arm_kg=0.17,
    forearm_kg=0.06,
)
LEAGUE_TEST_KID_CROUCH_RAD = 1.126  # the knee 0.080 above the ankle as in the proto
# the ankle servos' box (x, z of its centre, half sizes) in the foot's frame: its centre 0.0437
# above the ground as in the proto (0.01 above the ankle, whose foot box reaches 0.0337 below it)
_ANKLE_BOX_Z_M = 0.0437 - LEAGUE_TEST_KID_GEOMETRY.ankle_height_m
LEAGUE_TEST_KID_ANKLE_BOX_M = (-0.0205, _ANKLE_BOX_Z_M, 0.0415, 0.018, 0.0225)
# the thighs and shanks as boxes 0.05 deep and 0.062 wide, 0.004 forward of the leg's axis, the
# shank's reaching 0.0165 above the knee (the shank's boxes ``0.064 0.034 0.041`` at
# ``0 -0.058 -0.001`` and ``0.062 0.073 0.027`` at ``0 -0.02 0.016``, lines 1033-1050: 0.021
# behind its axis to 0.0295 in front, the second from 0.0165 above the knee): the knees' front
# 0.112 in front of the origin crouched (the proto's 0.109), and with the hips at 0.045 they
# leave 0.028 m between the legs, so a ball pushed into the knees meets their fronts
LEAGUE_TEST_KID_LEG_BOX_M = (0.025, 0.031, 0.004, 0.0165)


def league_test_kid(base: RobotModel) -> RobotModel:
    """The league's test robot, with the motors of ``base`` (the kid-size built-in robot)."""
    return RobotModel(
        name=LEAGUE_TEST_KID_NAME,
        field_class="kid",
        geometry=LEAGUE_TEST_KID_GEOMETRY,
        motors=base.motors,
        joint_armature=base.joint_armature,
        crouch_rad=LEAGUE_TEST_KID_CROUCH_RAD,
        ankle_box_m=LEAGUE_TEST_KID_ANKLE_BOX_M,
        leg_box_m=LEAGUE_TEST_KID_LEG_BOX_M,
    )
