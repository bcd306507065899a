"""``hlvs/Kick-v0``: one robot and the ball; walk to the ball and kick it into the goal at x > 0.

Reset (from the seed): the ball somewhere in the attacking half (``x`` in [0, 2.5] m, ``y`` in
[-1.5, 1.5] m), the robot ``ball_distance_m`` behind it, on the line from the goal centre through
the ball turned by up to ``bearing_noise_rad``, facing the ball within ``heading_noise_rad``.

Reward per step (metres, documented and stable across versions of this id)::

    0.5 x (robot-to-ball distance before - after)      approach
  + 2.0 x (ball-to-goal-centre distance before - after) progress of the ball
  + 10 when the ball is in the goal                      (terminates)
  - 1 when the robot falls (torso up axis below 60 deg)  (terminates)

The episode also terminates when the ball leaves the field elsewhere, and is truncated after
``max_episode_s`` of simulated time. ``info`` carries ``kick_distance_m`` (how far the ball moved
from where it was placed), ``ball_to_goal_m``, ``robot_to_ball_m``, ``goal``, ``fallen``,
``out`` and ``sim_time_ms``.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from contracts import field_for
from envs.base import HlvsEnv, Session
from envs.errors import EnvConfigError
from envs.frame import BALL_POS, UP_Z, Frame
from envs.session_spec import ResetOptions, ResetRequest, SessionSpec

APPROACH_WEIGHT = 0.5
PROGRESS_WEIGHT = 2.0
GOAL_REWARD = 10.0
FALL_PENALTY = 1.0
FALLEN_UP_Z = 0.5  # cos(60 deg)
MAX_EPISODE_S = 3600.0  # an hour of simulated time: far past any skill episode


class KickEnv(HlvsEnv):
    def __init__(
        self,
        *,
        field_class: str = "kid",
        model: str = "kid-default",
        camera: bool = False,
        perception: bool = False,
        perception_noise: float = 0.0,
        steps_per_action: int = 1,
        look: str = "fixed",
        texture_seed: int = 0,
        sensors: str = "ideal",
        max_episode_s: float = 15.0,
        ball_distance_m: tuple[float, float] = (0.3, 1.0),
        bearing_noise_rad: float = 0.6,
        heading_noise_rad: float = 0.3,
        remotes: int | str | None = None,
        render_mode: str | None = None,
        session: Session | None = None,
    ) -> None:
        low, high = ball_distance_m
        if not 0.15 <= low <= high:
            raise EnvConfigError(
                field="ball_distance_m",
                value=ball_distance_m,
                expected="(low, high) with 0.15 <= low <= high",
            )  # fmt: skip
        if not 0 < max_episode_s <= MAX_EPISODE_S:
            raise EnvConfigError(field="max_episode_s", value=max_episode_s,
                                 expected=f"seconds, > 0 and <= {MAX_EPISODE_S:g}")
        spec = SessionSpec(
            field_class=field_class, model=model, camera=camera or render_mode == "rgb_array",
            perception=perception, perception_noise=perception_noise,
            steps_per_action=steps_per_action,
            look=look, texture_seed=texture_seed, sensors=sensors,
        )  # fmt: skip
        super().__init__(
            spec=spec, other_robots=0, game=False, remotes=remotes, render_mode=render_mode,
            session=session,
        )  # fmt: skip
        self.field = field_for(field_class)
        self.goal_xy = np.array([self.field.half_length_m, 0.0])
        self.ball_distance_m = (float(low), float(high))
        self.bearing_noise_rad = bearing_noise_rad
        self.heading_noise_rad = heading_noise_rad
        self.max_steps = math.ceil(max_episode_s * 1000 / (8 * steps_per_action))
        self._steps = 0
        self._ball_start = np.zeros(2)
        self._last: tuple[Frame | None, tuple[float, float]] = (None, (0.0, 0.0))
        self._outcome: tuple[Frame | None, tuple[bool, bool, bool]] = (None, (False,) * 3)

    def reset_request(self, world_seed: int, options: ResetOptions) -> ResetRequest:
        rng = self.np_random
        bx = float(options.get("ball_x_m", rng.uniform(0.0, 2.5)))
        by = float(options.get("ball_y_m", rng.uniform(-1.5, 1.5)))
        distance = float(rng.uniform(*self.ball_distance_m))
        to_goal = math.atan2(self.goal_xy[1] - by, self.goal_xy[0] - bx)
        bearing = to_goal + math.pi + rng.uniform(-self.bearing_noise_rad, self.bearing_noise_rad)
        rx, ry = bx + distance * math.cos(bearing), by + distance * math.sin(bearing)
        heading = math.atan2(by - ry, bx - rx) + rng.uniform(
            -self.heading_noise_rad, self.heading_noise_rad
        )
        pose = options.get("robot_pose", (rx, ry, heading))
        return ResetRequest(
            seed=world_seed,
            learner_pose=(float(pose[0]), float(pose[1]), float(pose[2])),
            ball_xy=(bx, by),
        )

    def on_reset(self, frame: Frame) -> None:
        self._steps = 0
        self._ball_start = frame.truth[BALL_POS][:2].copy()
        self._last = (frame, self._measures(frame))

    def _measures(self, frame: Frame) -> tuple[float, float]:
        if self._last[0] is frame:
            return self._last[1]
        bx, by, _, _, _, _, rx, ry = frame.truth[:8].tolist()
        gx = self.field.half_length_m
        measures = math.hypot(bx - rx, by - ry), math.hypot(gx - bx, by)
        self._last = (frame, measures)
        return measures

    def outcome(self, frame: Frame) -> tuple[bool, bool, bool]:
        """(goal, fallen, out) for a frame."""
        if self._outcome[0] is frame:
            return self._outcome[1]
        result = self._judge_outcome(frame)
        self._outcome = (frame, result)
        return result

    def _judge_outcome(self, frame: Frame) -> tuple[bool, bool, bool]:
        x, y, z = frame.truth[BALL_POS].tolist()
        f = self.field
        r = f.ball_radius_m
        goal = x - r > f.half_length_m and abs(y) < f.goal_width_m / 2 and z < f.goal_height_m
        out = not goal and (abs(x) - r > f.half_length_m or abs(y) - r > f.half_width_m)
        fallen = bool(frame.truth[UP_Z] < FALLEN_UP_Z)
        return bool(goal), fallen, bool(out)

    def judge(self, previous: Frame, frame: Frame) -> tuple[float, bool, bool]:
        self._steps += 1
        rb0, bg0 = self._measures(previous)
        rb1, bg1 = self._measures(frame)
        reward = APPROACH_WEIGHT * (rb0 - rb1) + PROGRESS_WEIGHT * (bg0 - bg1)
        goal, fallen, out = self.outcome(frame)
        if goal:
            reward += GOAL_REWARD
        if fallen:
            reward -= FALL_PENALTY
        terminated = goal or fallen or out
        truncated = not terminated and self._steps >= self.max_steps
        return float(reward), terminated, truncated

    def info(self, frame: Frame) -> dict[str, Any]:
        rb, bg = self._measures(frame)
        goal, fallen, out = self.outcome(frame)
        bx, by = frame.truth[:2].tolist()
        sx, sy = self._ball_start.tolist()
        kick = math.hypot(bx - sx, by - sy)
        return {
            "sim_time_ms": frame.sim_time_ms,
            "kick_distance_m": kick,
            "ball_to_goal_m": bg,
            "robot_to_ball_m": rb,
            "goal": goal,
            "fallen": fallen,
            "out": out,
        }
