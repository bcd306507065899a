"""Learned skills in the robot: a policy file (plain arrays) and the motion that plays it.

Training writes the policy's weights with :func:`robot.learned.policy.save_policy`; the robot
runs the MLP with numpy (:class:`Policy`), so a robot image needs no training library.
"""

from __future__ import annotations

from robot.learned.motion import PolicyMotion
from robot.learned.policy import Policy, PolicyFileError, load_policy, save_policy

__all__ = ["Policy", "PolicyFileError", "PolicyMotion", "load_policy", "save_policy"]
