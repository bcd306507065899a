"""``hlvs/Match-v0``: control one robot of a team in a real match against stub robots.

The session runs the GameController and the automatic referee after every step (on simulated
time, see :mod:`envs.match_setup`); by default the learning robot is red player 1, alone in its
team, against a blue stub goalie and a blue stub striker, halves of ``half_duration_s``. The
observation adds ``game`` (state, score, seconds remaining, penalised, own kick-off).

Reward per step (documented and stable across versions of this id)::

    +1 for every goal of the learning robot's team, -1 for every goal against it
  + 0.1 x (ball-to-opponent-goal distance before - after), while PLAYING   shaping
  - 0.01 when the learning robot has fallen (torso up axis below 60 deg)  shaping

The episode terminates when the game is FINISHED (after the second half). ``info`` carries the
game view (state, score, half...), the referee events of the step and ``sim_time_ms``.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from contracts import ENVIRONMENT, MIN_PLAYING_S, field_for
from envs.base import HlvsEnv, Session
from envs.frame import BALL_POS, UP_Z, Frame, GameView
from envs.match_setup import default_stubs
from envs.session_spec import SessionSpec, StubSpec

GOAL_REWARD = 1.0
PROGRESS_WEIGHT = 0.1
FALLEN_PENALTY = 0.01
FALLEN_UP_Z = 0.5


class MatchEnv(HlvsEnv):
    def __init__(
        self,
        *,
        field_class: str = "kid",
        model: str = "kid-default",
        half_duration_s: float = ENVIRONMENT.half_duration_s,
        minimum_play_s: float = MIN_PLAYING_S,
        learner_pose: tuple[float, float, float] = (-1.0, 0.0, 0.0),
        stubs: tuple[StubSpec, ...] | None = None,
        camera: bool = False,
        perception: bool = False,
        perception_noise: float = 0.0,
        steps_per_action: int = 1,
        look: str = "fixed",
        texture_seed: int = 0,
        sensors: str = "ideal",
        remotes: int | str | None = None,
        render_mode: str | None = None,
        session: Session | None = None,
    ) -> None:
        stubs = default_stubs() if stubs is None else tuple(stubs)
        spec = SessionSpec(
            field_class=field_class, model=model, learner_pose=tuple(learner_pose),  # type: ignore[arg-type]
            stubs=stubs, referee=True, half_duration_s=half_duration_s,
            minimum_play_s=minimum_play_s,
            camera=camera or render_mode == "rgb_array", perception=perception,
            perception_noise=perception_noise, steps_per_action=steps_per_action,
            look=look, texture_seed=texture_seed, sensors=sensors,
        )  # fmt: skip
        super().__init__(
            spec=spec, other_robots=len(stubs), game=True, remotes=remotes,
            render_mode=render_mode, session=session,
        )  # fmt: skip
        self.field = field_for(field_class)

    def _ball_to_goal(self, frame: Frame) -> float:
        game: GameView = frame.game or {}
        goal_x = float(game.get("attack_sign", 1.0)) * self.field.half_length_m
        ball = frame.truth[BALL_POS]
        return float(np.hypot(goal_x - ball[0], ball[1]))

    def judge(self, previous: Frame, frame: Frame) -> tuple[float, bool, bool]:
        before: GameView = previous.game or {}
        after: GameView = frame.game or {}
        reward = GOAL_REWARD * (
            (after.get("score_own", 0) - before.get("score_own", 0))
            - (after.get("score_opponent", 0) - before.get("score_opponent", 0))
        )
        if after.get("state") == "PLAYING" and before.get("state") == "PLAYING":
            reward += PROGRESS_WEIGHT * (self._ball_to_goal(previous) - self._ball_to_goal(frame))
        if frame.truth[UP_Z] < FALLEN_UP_Z:
            reward -= FALLEN_PENALTY
        return float(reward), bool(after.get("finished")), False

    def info(self, frame: Frame) -> dict[str, Any]:
        return {"sim_time_ms": frame.sim_time_ms, "game": dict(frame.game or {}),
                "events": list(frame.events)}  # fmt: skip
