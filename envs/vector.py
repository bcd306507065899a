"""A vector environment spread over remote simulators: one environment per remote.

``make_vector("hlvs/Kick-v0", remotes=4)`` starts four simulator containers (or takes
``remotes="hlvs://a:7700,b:7700"``; ``remotes=None, num_envs=n`` keeps them in this process,
stepped one after the other). A step sends every remote its action first and then collects the
answers, so the remotes step at the same time. Environments that end are reset in the same
step (Gymnasium's ``SAME_STEP`` autoreset: ``infos["final_obs"]`` and ``infos["final_info"]``
hold what ended). Environment ``i`` is seeded with ``seed + i``. A remote that dies raises
:class:`envs.RemoteCrashed` from ``step()``; the next ``reset()`` replaces it when the pool
started it (``remotes=N`` or ``remotes="slurm:N"``).
"""

from __future__ import annotations

from typing import Any

import gymnasium as gym
import numpy as np
from gymnasium.vector import AutoresetMode, VectorEnv
from gymnasium.vector.utils import batch_space, concatenate, create_empty_array

from envs.base import HlvsEnv
from envs.remote import RemoteSession
from envs.remote_pool import RemotePool

_NUMBERS = (int, float, bool, np.float64, np.int64, np.bool_)


def make_vector(
    env_id: str,
    *,
    remotes: int | str | None,
    num_envs: int = 1,
    image: str | None = None,
    **kwargs: Any,
) -> VectorEnv:
    """One environment per remote; with ``remotes=None``, ``num_envs`` in-process environments
    stepped one after the other (batched as over remotes, without Gymnasium's per-step
    wrappers: the environments check their actions and time limits themselves)."""
    if remotes is None:
        local = []
        for _ in range(num_envs):
            env = gym.make(env_id, **kwargs).unwrapped
            assert isinstance(env, HlvsEnv)
            local.append(env)
        return RemoteVectorEnv(local, None)
    pool = RemotePool.open(remotes, image=image)
    try:
        spec_env = gym.make(env_id, session=_NullSession(), **kwargs).unwrapped
        assert isinstance(spec_env, HlvsEnv)
        sessions = [pool.session(i, spec_env.session_spec) for i in range(len(pool))]
        envs = []
        for index, session in enumerate(sessions):
            env = gym.make(env_id, session=session, **kwargs).unwrapped
            assert isinstance(env, HlvsEnv)
            env.attach_remote(pool, index)
            envs.append(env)
    except BaseException:
        pool.close()
        raise
    return RemoteVectorEnv(envs, pool)


class _NullSession:
    """Stands in while an environment is built only to read its session settings."""

    def close(self) -> None:
        return None


class RemoteVectorEnv(VectorEnv):
    """Environments on remotes of ``pool``, or in this process when ``pool`` is None."""

    metadata: dict[str, Any] = {"autoreset_mode": AutoresetMode.SAME_STEP}

    def __init__(self, envs: list[HlvsEnv], pool: RemotePool | None) -> None:
        self.envs = envs
        self.pool = pool
        self.num_envs = len(envs)
        self.single_observation_space = envs[0].observation_space
        self.single_action_space = envs[0].action_space
        self.observation_space = batch_space(self.single_observation_space, self.num_envs)
        self.action_space = batch_space(self.single_action_space, self.num_envs)
        self._obs = create_empty_array(self.single_observation_space, n=self.num_envs)
        space = self.single_observation_space
        # a Dict of Boxes (every hlvs observation): batched by writing rows in place
        self._rows: dict[str, np.ndarray] | None = None
        if isinstance(space, gym.spaces.Dict) and isinstance(self._obs, dict):
            if all(isinstance(s, gym.spaces.Box) for s in space.spaces.values()):
                self._rows = self._obs

    def reset(
        self, *, seed: int | list[int] | None = None, options: dict[str, Any] | None = None
    ) -> tuple[Any, dict[str, Any]]:
        seeds = (
            [None] * self.num_envs
            if seed is None
            else list(seed)
            if isinstance(seed, list)
            else [seed + i for i in range(self.num_envs)]
        )
        observations: list[Any] = []
        infos: list[dict[str, Any]] = []
        for i, env in enumerate(self.envs):
            obs, info = env.reset(seed=seeds[i], options=options)
            observations.append(obs)
            infos.append(info)
        return self._batch(observations), self._infos(infos)

    def _batch(self, observations: list[Any]) -> Any:
        if self._rows is None:
            return concatenate(self.single_observation_space, observations, self._obs)  # type: ignore[arg-type]
        for key, rows in self._rows.items():
            for i, obs in enumerate(observations):
                rows[i] = obs[key]
        return self._obs

    def _infos(self, infos: list[dict[str, Any]]) -> dict[str, Any]:
        """Gymnasium's batched infos (``infos[key]`` array, ``infos["_" + key]`` mask). When
        every environment reports the same keys with plain numbers (a step without an episode
        end), built in one go; otherwise key by key as Gymnasium does."""
        keys = infos[0].keys()
        if all(info.keys() == keys for info in infos) and all(
            type(value) in _NUMBERS for value in infos[0].values()
        ):
            out: dict[str, Any] = {}
            present = np.ones(self.num_envs, dtype=np.bool_)
            for key in keys:
                values = [info[key] for info in infos]
                out[key] = np.array(values, dtype=type(values[0]))
                out["_" + key] = present.copy()
            return out
        batched: dict[str, Any] = {}
        for i, info in enumerate(infos):
            batched = self._add_info(batched, info, i)
        return batched

    def step(self, actions: Any) -> tuple[Any, np.ndarray, np.ndarray, np.ndarray, dict[str, Any]]:
        batch = np.asarray(actions)
        if self.pool is None:
            return self._step_local(batch)
        for i, env in enumerate(self.envs):
            session = env.session
            assert isinstance(session, RemoteSession)
            session.send_step(env.targets(batch[i]))
        observations = []
        rewards = np.zeros(self.num_envs)
        terminated = np.zeros(self.num_envs, dtype=bool)
        truncated = np.zeros(self.num_envs, dtype=bool)
        infos: list[dict[str, Any]] = []
        for i, env in enumerate(self.envs):
            session = env.session
            assert isinstance(session, RemoteSession)
            obs, reward, term, trunc, info = env.finish_step(session.receive_step())
            observations.append(obs)
            rewards[i], terminated[i], truncated[i] = reward, term, trunc
            infos.append(info)
        return self._finish(observations, rewards, terminated, truncated, infos)

    def _step_local(
        self, batch: np.ndarray
    ) -> tuple[Any, np.ndarray, np.ndarray, np.ndarray, dict[str, Any]]:
        observations = []
        rewards = np.zeros(self.num_envs)
        terminated = np.zeros(self.num_envs, dtype=bool)
        truncated = np.zeros(self.num_envs, dtype=bool)
        infos: list[dict[str, Any]] = []
        for i, env in enumerate(self.envs):
            obs, reward, term, trunc, info = env.step(batch[i])
            observations.append(obs)
            rewards[i], terminated[i], truncated[i] = float(reward), term, trunc
            infos.append(info)
        return self._finish(observations, rewards, terminated, truncated, infos)

    def _finish(
        self,
        observations: list[Any],
        rewards: np.ndarray,
        terminated: np.ndarray,
        truncated: np.ndarray,
        infos: list[dict[str, Any]],
    ) -> tuple[Any, np.ndarray, np.ndarray, np.ndarray, dict[str, Any]]:
        """Environments that ended are reset in the same step (their last observation and
        info in ``final_obs`` and ``final_info``)."""
        for i, env in enumerate(self.envs):
            if terminated[i] or truncated[i]:
                final = {"final_obs": observations[i], "final_info": infos[i]}
                observations[i], info = env.reset()
                infos[i] = {**info, **final}
        return self._batch(observations), rewards, terminated, truncated, self._infos(infos)

    def close_extras(self, **kwargs: Any) -> None:
        for env in self.envs:
            env.session.close()
        if self.pool is not None:
            self.pool.close()
