"""Gymnasium environments over the soccer world, registered under the ``hlvs/`` namespace.

Use::

    import gymnasium as gym
    import envs  # registers hlvs/Kick-v0, hlvs/StandKick-v0 and hlvs/Match-v0

    env = gym.make("hlvs/Kick-v0", perception=True)            # world in this process
    env = gym.make("hlvs/Kick-v0", remotes=1)                   # one simulator container
    env = gym.make("hlvs/Kick-v0", remotes="hlvs://127.0.0.1:7700")  # a running simulator
    obs, info = env.reset(seed=1)
    obs, reward, terminated, truncated, info = env.step(env.action_space.sample())
    env.unwrapped.trainer.place_ball(1.0, 0.5)                  # trainer operations

Importing the package registers the ids (Gymnasium's convention) and, without a display,
selects offscreen rendering (``MUJOCO_GL=osmesa`` unless set: camera observations and monitor
videos; MuJoCo reads it when first imported).
"""

from __future__ import annotations

import os
from typing import TYPE_CHECKING

from contracts import lazy_exports

if not os.environ.get("DISPLAY"):
    os.environ.setdefault("MUJOCO_GL", "osmesa")
    os.environ.setdefault("PYOPENGL_PLATFORM", os.environ["MUJOCO_GL"])

import gymnasium  # noqa: E402

from envs.base import HlvsEnv, Session
from envs.errors import (
    EnvConfigError,
    EnvError,
    EnvStateError,
    RemoteCrashed,
    RemoteError,
    RemoteStartFailed,
    TrainerError,
)
from envs.frame import Frame
from envs.match import MatchEnv
from envs.session import LocalSession
from envs.session_spec import ResetOptions, ResetRequest, SessionSpec, StubSpec
from envs.skill import KickEnv
from envs.stand_kick import StandKickConfig, StandKickEnv

if TYPE_CHECKING:
    from envs.monitor import Monitor

ENV_IDS = ("hlvs/Kick-v0", "hlvs/StandKick-v0", "hlvs/Match-v0")


def register_envs() -> None:
    """Register the hlvs ids with Gymnasium (idempotent)."""
    registry = gymnasium.envs.registration.registry
    if "hlvs/Kick-v0" not in registry:
        gymnasium.register(id="hlvs/Kick-v0", entry_point="envs.skill:KickEnv")
    if "hlvs/StandKick-v0" not in registry:
        gymnasium.register(id="hlvs/StandKick-v0", entry_point="envs.stand_kick:StandKickEnv")
    if "hlvs/Match-v0" not in registry:
        gymnasium.register(id="hlvs/Match-v0", entry_point="envs.match:MatchEnv")


register_envs()

__all__ = [
    "ENV_IDS",
    "EnvConfigError",
    "EnvError",
    "EnvStateError",
    "Frame",
    "HlvsEnv",
    "KickEnv",
    "LocalSession",
    "MatchEnv",
    "Monitor",
    "RemoteCrashed",
    "RemoteError",
    "RemoteStartFailed",
    "ResetOptions",
    "ResetRequest",
    "Session",
    "SessionSpec",
    "StandKickConfig",
    "StandKickEnv",
    "StubSpec",
    "TrainerError",
    "register_envs",
]


if not TYPE_CHECKING:
    __getattr__, __dir__ = lazy_exports(__name__, {
        "envs.monitor": ("Monitor",),
    })
