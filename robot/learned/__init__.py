"""Learned skills in the robot: a policy file (plain arrays) and the motion that plays it.

Training writes the policy's weights with :func:`robot.learned.policy.save_policy`; the robot
runs the MLP with numpy (:class:`Policy`), so a robot image needs no training library.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from contracts import lazy_exports
from robot.learned.motion import PolicyMotion
from robot.learned.policy import Policy, PolicyFileError, load_policy, save_policy

if TYPE_CHECKING:
    from robot.learned.policy import (
        KICK_BALL_AHEAD_M,
        KICK_BALL_RIGHT_M,
        KICK_MODELS,
        LEARNT_SERVO_PID,
        kick_ball_offset,
    )

__all__ = [
    "KICK_BALL_AHEAD_M",
    "KICK_BALL_RIGHT_M",
    "KICK_MODELS",
    "LEARNT_SERVO_PID",
    "Policy",
    "PolicyFileError",
    "PolicyMotion",
    "kick_ball_offset",
    "load_policy",
    "save_policy",
]


if not TYPE_CHECKING:
    __getattr__, __dir__ = lazy_exports(__name__, {
        "robot.learned.policy": ("KICK_BALL_AHEAD_M", "KICK_BALL_RIGHT_M", "KICK_MODELS",
                                 "LEARNT_SERVO_PID", "kick_ball_offset"),
    })
