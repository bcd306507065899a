"""``hlvs/StandKick-v0``: kick the ball towards the goal from a stand, with the right foot.

The skill a striker plays once it has lined up behind the ball: at reset the robot stands in
its walking stance (``robot.motion.standing_posture``, eased into over the model's ``rise_s``
and held for ``settle_s`` so that it has settled), facing the opponent goal within
``heading_noise_rad``, with the ball where the stub striker lines it up for a right-foot kick
(``robot.learned.kick_ball_offset`` of the model: for kid-default ``BALL_AHEAD_M`` in front of
the torso and ``BALL_RIGHT_M`` to its right, each within ``ball_noise_m``; ``ball_closer_m``
nearer, for a curriculum that starts with the ball at the toe). The robot stands somewhere
between ``x`` 0.5 and 1.5 m of the attacking half.

``robot_class`` (``"kid"``, the default, or ``"adult"``) picks the pitch, its ball and goal, and
the class's default robot (``model`` names another); adult-default stands 1 s rising from the
straight legs it is placed with (bent at once, it tips over backwards) and finds the size-5
ball 0.33 m ahead and 0.15 m right of its torso, 3-4 cm in front of its right toe as the kid's.
The observation is laid out as the kid's: both models have the same 20 motors.

Observation: the robot API's sensors (as ``hlvs/Kick-v0``) and ``time``, the seconds since the
episode started (the robot API's clock, which a robot running the skill counts itself).
Action: the 20 motor position targets (rad).

Reward per step, shaped as kicking skills are learnt (an approach term, a contact bonus, the
ball's velocity towards the goal, a cost for standing still and for falling)::

    2.0 x (ball-to-goal-centre distance before - after)  the ball's velocity towards the goal
                                                          x 2 x the step's duration
  + approach_weight (1) x (toe-to-ball gap before - after), until the first touch
  + touch_bonus (0.5) at the first touch
  - still_penalty (0.01) per step before the first touch (standing still costs 0.47 in 1.5 s)
  - fall_penalty (3) when the robot falls (torso up axis below 60 deg)   (terminates)

The gap is the distance from the right toe (the front centre of the right sole, ``TOE_R`` of
the frame's truth) to the ball's surface. The ball lies still until the robot moves it, so the
first touch is the first step whose ball speed reaches ``TOUCH_SPEED_M_S`` (0.1 m/s). With
``approach_weight``, ``touch_bonus`` and ``still_penalty`` at 0 the reward is the plain one of
earlier versions (progress and falls).

The episode terminates when the ball leaves the field (a goal included) and is truncated after
``max_episode_s`` of simulated time. ``info`` carries ``kick_distance_m``, ``ball_speed_m_s``
(horizontal), ``max_ball_speed_m_s`` (in this episode), ``ball_to_goal_m``, ``toe_to_ball_m``
(the gap), ``touched``, ``ball_closer_m`` (the episode's), ``goal``, ``fallen``, ``out`` and
``sim_time_ms``.

:class:`StandKickConfig` holds the settings, shared with the MJX vector
(:class:`envs.mjx_vector.MjxStandKickVector`); :func:`stand_kick_reward` is the reward both
compute (on floats here, on JAX arrays there).
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, fields
from typing import Any

import numpy as np
from gymnasium import spaces

from envs.base import Session
from envs.errors import EnvConfigError
from envs.frame import BALL_POS, BALL_VEL, ROBOT_XY, ROBOT_YAW, TOE_R, Frame
from envs.session_spec import FIELD_CLASSES, ResetOptions, ResetRequest
from envs.skill import PROGRESS_WEIGHT, KickEnv
from envs.spaces import observe
from robot.learned import KICK_BALL_AHEAD_M, KICK_BALL_RIGHT_M, KICK_MODELS, kick_ball_offset
from robot.motion import kinematics, standing_posture
from simulator.world import MOTOR_NAMES

BALL_AHEAD_M = KICK_BALL_AHEAD_M  # the stub striker lines the ball up there for the policy
BALL_RIGHT_M = KICK_BALL_RIGHT_M  # (kid-default's; robot.learned.kick_ball_offset per model)
STAND_FALL_PENALTY = 3.0
APPROACH_WEIGHT = 1.0
TOUCH_BONUS = 0.5
STILL_PENALTY = 0.01
TOUCH_SPEED_M_S = 0.1
MAX_BALL_CLOSER_M = 0.04
TIME_LIMIT_S = 1e4


@dataclass(frozen=True, kw_only=True)
class StandKickConfig:
    """The settings of ``hlvs/StandKick-v0`` (see the module), checked when made."""

    robot_class: str = "kid"
    model: str = ""  # "": the class's default robot, "<robot_class>-default"
    steps_per_action: int = 4
    max_episode_s: float = 1.5
    settle_s: float = 0.5
    ball_noise_m: float = 0.02
    ball_closer_m: float = 0.0
    heading_noise_rad: float = 0.15
    fall_penalty: float = STAND_FALL_PENALTY
    approach_weight: float = APPROACH_WEIGHT
    touch_bonus: float = TOUCH_BONUS
    still_penalty: float = STILL_PENALTY

    def __post_init__(self) -> None:
        if self.robot_class not in FIELD_CLASSES:
            raise EnvConfigError(field="robot_class", value=self.robot_class,
                                 expected="'kid' or 'adult'", choices=FIELD_CLASSES)  # fmt: skip
        if not self.model:
            object.__setattr__(self, "model", f"{self.robot_class}-default")
        try:
            kick_ball_offset(self.model)
        except KeyError:
            raise EnvConfigError(field="model", value=self.model,
                                 expected="a robot model with a stand-kick ball spot: "
                                 + ", ".join(KICK_MODELS), choices=KICK_MODELS) from None
        if not isinstance(self.steps_per_action, int) or self.steps_per_action < 1:
            raise EnvConfigError(field="steps_per_action", value=self.steps_per_action,
                                 expected="an integer >= 1")  # fmt: skip
        if not 0.0 <= self.settle_s <= 5.0:
            raise EnvConfigError(field="settle_s", value=self.settle_s, expected="0..5 s")
        if not 0.0 <= self.ball_noise_m <= 0.05:
            raise EnvConfigError(field="ball_noise_m", value=self.ball_noise_m,
                                 expected="0..0.05 m")  # fmt: skip
        check_ball_closer(self.ball_closer_m)
        for name in ("fall_penalty", "approach_weight", "touch_bonus", "still_penalty"):
            value = getattr(self, name)
            if not (isinstance(value, int | float) and math.isfinite(value) and value >= 0):
                raise EnvConfigError(field=name, value=value, expected="a number >= 0")

    @classmethod
    def of(cls, options: dict[str, Any]) -> StandKickConfig:
        """The config of keyword arguments (an unknown name is an EnvConfigError)."""
        names = [f.name for f in fields(cls)]
        for name in options:
            if name not in names:
                raise EnvConfigError(field="setting", value=name,
                                     expected=f"a setting of hlvs/StandKick-v0: {', '.join(names)}",
                                     choices=names)  # fmt: skip
        return cls(**options)

    def as_dict(self) -> dict[str, Any]:
        return asdict(self)


def check_ball_closer(value: float) -> float:
    if not 0.0 <= value <= MAX_BALL_CLOSER_M:
        raise EnvConfigError(field="ball_closer_m", value=value,
                             expected=f"0..{MAX_BALL_CLOSER_M} m")  # fmt: skip
    return float(value)


def stand_kick_reward(
    config: StandKickConfig, *, progress: Any, gap_before: Any, gap_after: Any,
    touched_before: Any, touched: Any, fallen: Any, fall_penalty: Any,
) -> Any:  # fmt: skip
    """One step's reward (see the module): floats, or arrays of one shape (flags as 0/1)."""
    before = 1.0 - touched_before  # 1 until the first touch
    return (
        PROGRESS_WEIGHT * progress
        + config.approach_weight * (gap_before - gap_after) * before
        + config.touch_bonus * touched * before
        - config.still_penalty * before * (1.0 - touched)
        - fall_penalty * fallen
    )


class StandKickEnv(KickEnv):
    def __init__(
        self,
        *,
        remotes: int | str | None = None,
        render_mode: str | None = None,
        session: Session | None = None,
        camera: bool = False,
        **options: Any,
    ) -> None:
        config = StandKickConfig.of(options)
        super().__init__(
            field_class=config.robot_class, model=config.model, camera=camera,
            steps_per_action=config.steps_per_action, max_episode_s=config.max_episode_s,
            heading_noise_rad=config.heading_noise_rad, remotes=remotes,
            render_mode=render_mode, session=session,
        )  # fmt: skip
        self.config = config
        assert isinstance(self.observation_space, spaces.Dict)
        self.observation_space = spaces.Dict(
            {**self.observation_space.spaces,
             "time": spaces.Box(0.0, TIME_LIMIT_S, (1,), np.float32)}
        )  # fmt: skip
        self.ball_noise_m = config.ball_noise_m
        self.fall_penalty = float(config.fall_penalty)  # a trainer may change it between steps
        self.ball_closer_m = config.ball_closer_m  # and this between episodes (a curriculum)
        step_ms = 8 * config.steps_per_action
        self.settle_steps = math.ceil(config.settle_s * 1000 / step_ms)
        self.rise_steps = math.ceil(kinematics(config.model).rise_s * 1000 / step_ms)
        stance = standing_posture(config.model)
        self.stance = np.array([stance.get(name, 0.0) for name in MOTOR_NAMES])
        self._start_ms = 0
        self._max_speed = 0.0
        self._touched = False
        self.ball_spot = kick_ball_offset(config.model)  # (ahead, right) of the torso
        self._ball_offset = self.ball_spot
        self._closer = 0.0  # the episode's ball_closer_m

    def reset_request(self, world_seed: int, options: ResetOptions) -> ResetRequest:
        rng = self.np_random
        rx, ry = float(rng.uniform(0.5, 1.5)), float(rng.uniform(-1.0, 1.0))
        yaw = math.atan2(-ry, self.goal_xy[0] - rx)
        yaw += float(rng.uniform(-self.heading_noise_rad, self.heading_noise_rad))
        self._closer = check_ball_closer(self.ball_closer_m)
        ahead, right = self.ball_spot
        self._ball_offset = (
            ahead - self._closer + float(rng.uniform(-self.ball_noise_m, self.ball_noise_m)),
            right + float(rng.uniform(-self.ball_noise_m, self.ball_noise_m)),
        )
        # the ball waits far away while the robot settles, then goes to its foot
        return ResetRequest(seed=world_seed, learner_pose=(rx, ry, yaw), ball_xy=(-3.0, 0.0))

    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[dict[str, Any], dict[str, Any]]:
        super().reset(seed=seed, options=options)
        frame = self.frame
        assert frame is not None
        # into the stance before the skill starts: eased in over the model's rise (adult-default
        # bent at the servos' full speed from straight legs tips over backwards), then held
        space: Any = self.observation_space
        start = np.asarray(observe(frame, space)["joints"], np.float64)
        for k in range(self.rise_steps):
            frame = self.session.step(start + (k + 1) / self.rise_steps * (self.stance - start))
        for _ in range(self.settle_steps):
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
        self._touched = False

    def finish_step(self, frame: Frame) -> tuple[dict[str, Any], float, bool, bool, dict[str, Any]]:
        _, reward, terminated, truncated, info = super().finish_step(frame)
        return self._observe(frame), reward, terminated, truncated, info

    def _observe(self, frame: Frame) -> dict[str, Any]:
        obs = observe(frame, self.observation_space)  # type: ignore[arg-type]
        obs["time"] = np.array([(frame.sim_time_ms - self._start_ms) / 1000.0], np.float32)
        return obs

    def gap(self, frame: Frame) -> float:
        """The right toe's distance to the ball's surface (m, 0 in contact)."""
        toe = frame.truth[TOE_R]
        ball = frame.truth[BALL_POS]
        return max(0.0, float(np.linalg.norm(toe - ball)) - self.field.ball_radius_m)

    def judge(self, previous: Frame, frame: Frame) -> tuple[float, bool, bool]:
        self._steps += 1
        _, bg0 = self._measures(previous)
        _, bg1 = self._measures(frame)
        goal, fallen, out = self.outcome(frame)
        speed = _speed(frame)
        touched_before = self._touched
        self._touched = touched_before or speed >= TOUCH_SPEED_M_S
        reward = stand_kick_reward(
            self.config, progress=bg0 - bg1, gap_before=self.gap(previous),
            gap_after=self.gap(frame), touched_before=float(touched_before),
            touched=float(self._touched), fallen=float(fallen), fall_penalty=self.fall_penalty,
        )  # fmt: skip
        self._max_speed = max(self._max_speed, speed)
        terminated = goal or fallen or out
        truncated = not terminated and self._steps >= self.max_steps
        return float(reward), terminated, truncated

    def info(self, frame: Frame) -> dict[str, Any]:
        out = super().info(frame)
        out.pop("robot_to_ball_m", None)
        out["ball_speed_m_s"] = _speed(frame)
        out["max_ball_speed_m_s"] = self._max_speed
        out["toe_to_ball_m"] = self.gap(frame)
        out["touched"] = self._touched
        out["ball_closer_m"] = self._closer
        return out


def _speed(frame: Frame) -> float:
    vx, vy, _ = frame.truth[BALL_VEL].tolist()
    return math.hypot(vx, vy)
