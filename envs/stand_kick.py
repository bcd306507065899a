"""``hlvs/StandKick-v0``: kick the ball towards the goal from a stand, with the right foot.

The skill a striker plays once it has lined up behind the ball: at reset the robot stands in
its walking stance (``robot.motion.standing_posture``, held for ``settle_s`` so that it has
settled), facing the opponent goal within ``heading_noise_rad``, with the ball where the stub
striker lines it up for a right-foot kick (``BALL_AHEAD_M`` in front of the torso and
``BALL_RIGHT_M`` to its right, each within ``ball_noise_m``). The robot stands somewhere between
``x`` 0.5 and 1.5 m of the attacking half.

Observation: the robot API's sensors (as ``hlvs/Kick-v0``) and ``time``, the seconds since the
episode started (the robot API's clock, which a robot running the skill counts itself).
Action: the 20 motor position targets (rad).

Reward per step (metres)::

    2.0 x (ball-to-goal-centre distance before - after)   progress of the ball
  - fall_penalty (3) when the robot falls (torso up axis below 60 deg)   (terminates)

The episode terminates when the ball leaves the field (a goal included) and is truncated after
``max_episode_s`` of simulated time. ``info`` carries ``kick_distance_m``, ``ball_speed_m_s``
(horizontal), ``max_ball_speed_m_s`` (in this episode), ``ball_to_goal_m``, ``goal``,
``fallen``, ``out`` and ``sim_time_ms``.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from gymnasium import spaces

from envs.base import Session
from envs.errors import EnvConfigError
from envs.frame import BALL_VEL, ROBOT_XY, ROBOT_YAW, Frame
from envs.session_spec import ResetOptions, ResetRequest
from envs.skill import PROGRESS_WEIGHT, KickEnv
from envs.spaces import observe
from robot.learned import KICK_BALL_AHEAD_M, KICK_BALL_RIGHT_M
from robot.motion import standing_posture
from simulator.world import MOTOR_NAMES

BALL_AHEAD_M = KICK_BALL_AHEAD_M  # the stub striker lines the ball up there for the policy
BALL_RIGHT_M = KICK_BALL_RIGHT_M
STAND_FALL_PENALTY = 3.0
TIME_LIMIT_S = 1e4


class StandKickEnv(KickEnv):
    def __init__(
        self,
        *,
        model: str = "kid-default",
        steps_per_action: int = 4,
        max_episode_s: float = 1.5,
        settle_s: float = 0.5,
        ball_noise_m: float = 0.02,
        heading_noise_rad: float = 0.15,
        fall_penalty: float = STAND_FALL_PENALTY,
        remotes: int | str | None = None,
        render_mode: str | None = None,
        session: Session | None = None,
        camera: bool = False,
    ) -> None:
        if not 0.0 <= settle_s <= 5.0:
            raise EnvConfigError(field="settle_s", value=settle_s, expected="0 <= settle_s <= 5")
        if not 0.0 <= ball_noise_m <= 0.05:
            raise EnvConfigError(field="ball_noise_m", value=ball_noise_m, expected="0..0.05 m")
        super().__init__(
            field_class="kid", model=model, camera=camera, steps_per_action=steps_per_action,
            max_episode_s=max_episode_s, heading_noise_rad=heading_noise_rad, remotes=remotes,
            render_mode=render_mode, session=session,
        )  # fmt: skip
        assert isinstance(self.observation_space, spaces.Dict)
        self.observation_space = spaces.Dict(
            {**self.observation_space.spaces,
             "time": spaces.Box(0.0, TIME_LIMIT_S, (1,), np.float32)}
        )  # fmt: skip
        self.ball_noise_m = ball_noise_m
        self.fall_penalty = float(fall_penalty)
        self.settle_steps = math.ceil(settle_s * 1000 / (8 * steps_per_action))
        stance = standing_posture(model)
        self.stance = np.array([stance.get(name, 0.0) for name in MOTOR_NAMES])
        self._start_ms = 0
        self._max_speed = 0.0
        self._ball_offset = (BALL_AHEAD_M, BALL_RIGHT_M)

    def reset_request(self, world_seed: int, options: ResetOptions) -> ResetRequest:
        rng = self.np_random
        rx, ry = float(rng.uniform(0.5, 1.5)), float(rng.uniform(-1.0, 1.0))
        yaw = math.atan2(-ry, self.goal_xy[0] - rx)
        yaw += float(rng.uniform(-self.heading_noise_rad, self.heading_noise_rad))
        self._ball_offset = (
            BALL_AHEAD_M + float(rng.uniform(-self.ball_noise_m, self.ball_noise_m)),
            BALL_RIGHT_M + float(rng.uniform(-self.ball_noise_m, self.ball_noise_m)),
        )
        # the ball waits far away while the robot settles, then goes to its foot
        return ResetRequest(seed=world_seed, learner_pose=(rx, ry, yaw), ball_xy=(-3.0, 0.0))

    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[dict[str, Any], dict[str, Any]]:
        super().reset(seed=seed, options=options)
        frame = self.frame
        assert frame is not None
        for _ in range(self.settle_steps):  # into the stance before the skill starts
            frame = self.session.step(self.stance)
        rx, ry = frame.truth[ROBOT_XY].tolist()
        yaw = float(frame.truth[ROBOT_YAW])
        ahead, right = self._ball_offset
        c, s = math.cos(yaw), math.sin(yaw)
        self.session.place_ball(rx + ahead * c + right * s, ry + ahead * s - right * c)
        frame = self.session.step(self.stance)
        self.frame = frame
        self.on_reset(frame)
        return self._observe(frame), self.info(frame)

    def on_reset(self, frame: Frame) -> None:
        super().on_reset(frame)
        self._start_ms = frame.sim_time_ms
        self._max_speed = 0.0

    def finish_step(self, frame: Frame) -> tuple[dict[str, Any], float, bool, bool, dict[str, Any]]:
        _, reward, terminated, truncated, info = super().finish_step(frame)
        return self._observe(frame), reward, terminated, truncated, info

    def _observe(self, frame: Frame) -> dict[str, Any]:
        obs = observe(frame, self.observation_space)  # type: ignore[arg-type]
        obs["time"] = np.array([(frame.sim_time_ms - self._start_ms) / 1000.0], np.float32)
        return obs

    def judge(self, previous: Frame, frame: Frame) -> tuple[float, bool, bool]:
        self._steps += 1
        _, bg0 = self._measures(previous)
        _, bg1 = self._measures(frame)
        reward = PROGRESS_WEIGHT * (bg0 - bg1)
        goal, fallen, out = self.outcome(frame)
        if fallen:
            reward -= self.fall_penalty
        self._max_speed = max(self._max_speed, _speed(frame))
        terminated = goal or fallen or out
        truncated = not terminated and self._steps >= self.max_steps
        return float(reward), terminated, truncated

    def info(self, frame: Frame) -> dict[str, Any]:
        out = super().info(frame)
        out.pop("robot_to_ball_m", None)
        out["ball_speed_m_s"] = _speed(frame)
        out["max_ball_speed_m_s"] = self._max_speed
        return out


def _speed(frame: Frame) -> float:
    vx, vy, _ = frame.truth[BALL_VEL].tolist()
    return math.hypot(vx, vy)
