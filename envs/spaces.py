"""Observation and action spaces, from the robot model (the robot API's own quantities).

Action: motor position targets (rad) for the 20 motors in ``MOTOR_NAMES`` order, bounded by each
joint's range. Observation (a ``Dict``):

- ``joints`` (20): joint angles (rad), ``accelerometer`` (3, m/s^2), ``gyro`` (3, rad/s),
  ``forces`` (8, N): the sensors the robot API reports every step, clipped to the space bounds;
- ``camera`` (optional): the head camera image, 240 x 320 x 3 uint8 in B, G, R order as the robot
  API sends it;
- ``perception`` (optional): idealised perception in the camera frame
  (:mod:`envs.perception`): ``ball`` (4), ``goal_posts`` (4, 4), ``lines`` (33, 7),
  ``robots`` (other robots, 5 columns);
- ``game`` (match environments): ``state`` (0 INITIAL .. 4 FINISHED), ``score`` (own,
  opponent), ``secs_remaining``, ``penalised``, ``own_kickoff``.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from gymnasium import spaces

from envs.frame import ACCEL, FORCES, GYRO, JOINTS, Frame, GameView
from envs.perception import LINE_COUNT
from simulator.world import robot_model

ACCEL_LIMIT = 500.0
GYRO_LIMIT = 100.0
FORCE_LIMIT = 5000.0
GAME_STATES = ("INITIAL", "READY", "SET", "PLAYING", "FINISHED")
F32 = np.float32
_LOW = np.array([-math.pi] * 20 + [-ACCEL_LIMIT] * 3 + [-GYRO_LIMIT] * 3 + [0.0] * 8)
_HIGH = np.array([math.pi] * 20 + [ACCEL_LIMIT] * 3 + [GYRO_LIMIT] * 3 + [FORCE_LIMIT] * 8)


def action_space(model: str) -> spaces.Box:
    motors = robot_model(model).motors
    low = np.array([m.lower_rad for m in motors], dtype=F32)
    high = np.array([m.upper_rad for m in motors], dtype=F32)
    return spaces.Box(low=low, high=high, dtype=F32)


def observation_space(
    model: str, *, camera: bool, perception: bool, other_robots: int, game: bool
) -> spaces.Dict:
    n = len(robot_model(model).motors)
    items: dict[str, spaces.Space[Any]] = {
        "joints": spaces.Box(-math.pi, math.pi, (n,), F32),
        "accelerometer": spaces.Box(-ACCEL_LIMIT, ACCEL_LIMIT, (3,), F32),
        "gyro": spaces.Box(-GYRO_LIMIT, GYRO_LIMIT, (3,), F32),
        "forces": spaces.Box(0.0, FORCE_LIMIT, (8,), F32),
    }
    if camera:
        cam = robot_model(model).camera
        items["camera"] = spaces.Box(0, 255, (cam.height, cam.width, 3), np.uint8)
    if perception:
        big = 1000.0
        items["perception"] = spaces.Dict(
            {
                "ball": spaces.Box(-big, big, (4,), F32),
                "goal_posts": spaces.Box(-big, big, (4, 4), F32),
                "lines": spaces.Box(-big, big, (LINE_COUNT, 7), F32),
                "robots": spaces.Box(-big, big, (other_robots, 5), F32),
            }
        )
    if game:
        items["game"] = spaces.Dict(
            {
                "state": spaces.Discrete(len(GAME_STATES)),
                "score": spaces.Box(0, 1000, (2,), np.int64),
                "secs_remaining": spaces.Box(-1e4, 1e4, (1,), F32),
                "penalised": spaces.Discrete(2),
                "own_kickoff": spaces.Discrete(2),
            }
        )
    return spaces.Dict(items)


def observe(frame: Frame, space: spaces.Dict) -> dict[str, Any]:
    """The observation of ``frame`` for ``space`` (values clipped into the bounds)."""
    s = np.minimum(np.maximum(frame.sensors, _LOW), _HIGH).astype(F32)
    obs: dict[str, Any] = {
        "joints": s[JOINTS],
        "accelerometer": s[ACCEL],
        "gyro": s[GYRO],
        "forces": s[FORCES],
    }
    if "camera" in space.spaces:
        if frame.image is None:
            raise ValueError("the session sent no camera image")
        obs["camera"] = frame.image
    if "perception" in space.spaces:
        p = frame.perception or {}
        sub = space.spaces["perception"]
        assert isinstance(sub, spaces.Dict)
        obs["perception"] = {
            key: np.clip(np.asarray(p[key], dtype=F32), -1000.0, 1000.0).reshape(box.shape)
            for key, box in sub.spaces.items()
        }
    if "game" in space.spaces:
        g: GameView = frame.game or {}
        obs["game"] = {
            "state": GAME_STATES.index(str(g.get("state", "INITIAL"))),
            "score": np.array([g.get("score_own", 0), g.get("score_opponent", 0)], np.int64),
            "secs_remaining": np.array([g.get("secs_remaining", 0.0)], F32),
            "penalised": int(bool(g.get("penalised"))),
            "own_kickoff": int(bool(g.get("own_kickoff"))),
        }
    return obs
