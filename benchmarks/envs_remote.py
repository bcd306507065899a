"""The remote part of ``hlvs bench envs --remotes N``: one remote over TCP and vector
environments over 1, 2, 4... remotes, all on containers of one pool started for the run."""

from __future__ import annotations

import time
from typing import Any

import gymnasium as gym
import numpy as np

from benchmarks.envs import _actions
from envs.remote import RemotePool
from envs.vector import make_vector


def _env_rate(address: str, steps: int, seed: int) -> float:
    env = gym.make("hlvs/Kick-v0", remotes=address, max_episode_s=1e6)
    env.reset(seed=seed)
    actions = _actions(steps, seed)
    started = time.perf_counter()
    for a in actions:
        env.step(a)
    rate = steps / (time.perf_counter() - started)
    env.close()
    return rate


def _vector_rate(addresses: str, size: int, steps: int, seed: int) -> float:
    vec = make_vector("hlvs/Kick-v0", remotes=addresses, max_episode_s=1e6)
    vec.reset(seed=seed)
    actions = _actions(steps, seed)
    batch = np.repeat(actions[:, None, :], size, axis=1)
    started = time.perf_counter()
    for a in batch:
        vec.step(a)
    rate = steps * size / (time.perf_counter() - started)
    vec.close()
    return rate


def bench_remotes(*, remotes: int, sizes: list[int], steps: int, seed: int) -> dict[str, Any]:
    count = max([remotes, *sizes])
    started = time.perf_counter()
    pool = RemotePool.open(count)
    start_s = time.perf_counter() - started
    try:
        urls = [str(a) for a in pool.addresses]
        one = _env_rate(urls[0], steps, seed)
        vector = {str(k): round(_vector_rate(",".join(urls[:k]), k, steps, seed), 1) for k in sizes}
    finally:
        pool.close()
    return {
        "remote_tcp": {"env_steps_per_s": round(one, 1), "steps": steps},
        "vector_env_steps_per_s": vector,
        "remotes_started": count,
        "remotes_start_s": round(start_s, 2),
    }
