"""The standing posture the gait starts from and returns to."""

from __future__ import annotations

from robot.motion.ik import FootTarget
from robot.motion.keyframes import body_pose
from robot.motion.walk import default_walk_params


def standing_posture(model: str = "kid-default") -> dict[str, float]:
    """Motor targets of the walk-ready stance: knees bent to the gait's hip height, slight
    forward lean, arms resting, head straight."""
    from robot.motion.models import kinematics

    kin = kinematics(model)
    params = default_walk_params(model)
    foot = FootTarget(params.foot_x_offset_m, params.foot_y_offset_m, -params.hip_height_m)
    right = FootTarget(params.foot_x_offset_m, -params.foot_y_offset_m, -params.hip_height_m)
    return body_pose(kin, left=foot, right=right, torso_pitch_rad=params.torso_pitch_rad)
