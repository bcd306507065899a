"""``remotes=N``: simulator containers started, health-checked, replaced after a crash, removed
by label at close (real Docker engine, the project's simulator image)."""

from __future__ import annotations

import docker
import gymnasium as gym
import numpy as np
import pytest

import envs  # noqa: F401
from envs import RemoteCrashed
from envs.docker_pool import LABEL_POOL
from envs.vector import make_vector

pytestmark = pytest.mark.docker


def _pool_containers(client: docker.DockerClient, pool_id: str) -> list[object]:
    return list(client.containers.list(all=True, filters={"label": f"{LABEL_POOL}={pool_id}"}))


def test_one_remote_container_runs_an_episode_and_is_replaced_after_a_crash(
    docker_client: docker.DockerClient,
) -> None:
    env = gym.make("hlvs/Kick-v0", remotes=1)
    pool = env.unwrapped._owner
    pool_id = pool.launcher.pool_id
    socket_root = pool.launcher.socket_root
    try:
        # a local engine: the remote answers on its Unix socket (mounted from a folder of ours)
        assert str(pool.addresses[0]).startswith(f"hlvs+unix://{socket_root}/")
        obs, info = env.reset(seed=3)
        steps = 0
        for _ in range(100):
            obs, reward, terminated, truncated, info = env.step(np.zeros(20, np.float32))
            steps += 1
        assert env.observation_space.contains(obs) and info["sim_time_ms"] == 800
        first = pool.launcher.containers[0]
        docker_client.containers.get(first).kill()
        with pytest.raises(RemoteCrashed) as crashed:
            for _ in range(50):
                env.step(np.zeros(20, np.float32))
        assert "exited with code 137" in crashed.value.cause
        env.reset(seed=3)  # a new container takes its place
        assert pool.launcher.containers[0] != first
        *_, info = env.step(np.zeros(20, np.float32))
        assert info["sim_time_ms"] == 8
        assert len(_pool_containers(docker_client, pool_id)) == 1
    finally:
        env.close()
    assert _pool_containers(docker_client, pool_id) == []
    assert not socket_root.exists()


def test_vector_env_over_two_remotes(docker_client: docker.DockerClient) -> None:
    vec = make_vector("hlvs/Kick-v0", remotes=2)
    pool_id = vec.pool.launcher.pool_id
    try:
        obs, infos = vec.reset(seed=5)
        assert obs["joints"].shape == (2, 20)
        for _ in range(20):
            obs, rewards, terminated, truncated, infos = vec.step(np.zeros((2, 20), np.float32))
        assert rewards.shape == (2,)
        assert not np.array_equal(obs["joints"][0], obs["joints"][1])  # different seeds
        assert len(_pool_containers(docker_client, pool_id)) == 2
    finally:
        vec.close()
    assert _pool_containers(docker_client, pool_id) == []
