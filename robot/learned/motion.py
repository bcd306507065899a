"""Plays a learned skill in the robot: the policy chooses targets from the robot's readings.

Like the keyframe motions (:class:`robot.motion.KeyframeMotion`), call :meth:`step` every
control tick until :attr:`done`; before it, :meth:`sense` gives the readings of this tick. The
policy chooses a new action every ``control_period_ms`` of the skill's own clock (it starts at
0 with the first tick, as the training episode did) and holds it in between.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np

from robot.learned.policy import FloatArray, Policy


class PolicyMotion:
    def __init__(self, policy: Policy) -> None:
        self.policy = policy
        self._elapsed_s = 0.0
        self._next_decision_s = 0.0
        self._readings: tuple[Mapping[str, float], Sequence[float], Sequence[float]] | None = None
        self._targets: FloatArray = policy.stance.copy()
        self.decisions = 0

    @property
    def done(self) -> bool:
        return self._elapsed_s >= self.policy.duration_s

    @property
    def elapsed_s(self) -> float:
        return self._elapsed_s

    def sense(
        self,
        joints: Mapping[str, float],
        accel: Sequence[float] | None,
        gyro: Sequence[float] | None,
    ) -> None:
        """The readings of this tick (a missing IMU reads as standing still)."""
        self._readings = (joints, accel or (0.0, 0.0, 9.81), gyro or (0.0, 0.0, 0.0))

    def step(self, dt_s: float) -> dict[str, float]:
        if self._readings is not None and self._elapsed_s + 1e-9 >= self._next_decision_s:
            joints, accel, gyro = self._readings
            observation = self.policy.observation(joints, accel, gyro, self._elapsed_s)
            self._targets = self.policy.act(observation)
            self._next_decision_s += self.policy.control_period_ms / 1000.0
            self.decisions += 1
        self._elapsed_s += dt_s
        return dict(zip(self.policy.motors, np.asarray(self._targets).tolist(), strict=True))
