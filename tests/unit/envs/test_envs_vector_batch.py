"""The remote vector environment batches observations and infos exactly as Gymnasium does
(its own row writes and one-go infos are only faster)."""

from __future__ import annotations

from typing import Any

import gymnasium as gym
import numpy as np
from gymnasium.vector.utils import concatenate, create_empty_array

import envs  # noqa: F401
from envs.base import HlvsEnv
from envs.vector import RemoteVectorEnv


def _gymnasium_infos(vec: RemoteVectorEnv, infos: list[dict[str, Any]]) -> dict[str, Any]:
    out: dict[str, Any] = {}
    for i, info in enumerate(infos):
        out = vec._add_info(out, info, i)
    return out


def _same(a: Any, b: Any) -> None:
    if isinstance(a, dict):
        assert isinstance(b, dict) and a.keys() == b.keys()
        for key in a:
            _same(a[key], b[key])
    elif isinstance(a, np.ndarray) and a.dtype != object:
        assert isinstance(b, np.ndarray) and a.dtype == b.dtype and np.array_equal(a, b)
    elif isinstance(a, np.ndarray):
        assert isinstance(b, np.ndarray) and len(a) == len(b)
        for x, y in zip(a, b, strict=True):
            _same(x, y)
    else:
        assert a == b


def test_observations_and_infos_batch_as_gymnasium_does() -> None:
    made = [gym.make("hlvs/Kick-v0").unwrapped for _ in range(3)]
    vec = RemoteVectorEnv([e for e in made if isinstance(e, HlvsEnv)], pool=None)  # type: ignore[arg-type]
    try:
        steps = []
        for i, env in enumerate(made):
            env.reset(seed=10 + i)
            steps.append(env.step(np.full(20, 0.01 * i, np.float32)))
        observations = [s[0] for s in steps]
        infos = [s[4] for s in steps]
        space = vec.single_observation_space
        expected = concatenate(space, observations, create_empty_array(space, n=3))
        _same(dict(vec._batch(observations)), dict(expected))
        _same(vec._infos(infos), _gymnasium_infos(vec, infos))
        # an episode that ended: final_obs / final_info in one environment only
        ended = [dict(infos[0]), {**infos[1], "final_obs": observations[1],
                                  "final_info": dict(infos[1])}, dict(infos[2])]  # fmt: skip
        _same(vec._infos(ended), _gymnasium_infos(vec, ended))
        mixed = [{"a": 1}, {"a": 2.5}, {"a": 3}]  # Gymnasium keeps the first one's type
        _same(vec._infos(mixed), _gymnasium_infos(vec, mixed))
    finally:
        for env in made:
            env.close()
