"""``remotes=N``: simulator containers started, health-checked, replaced after a crash, removed
by label at close (real Docker engine, the project's simulator image)."""

from __future__ import annotations

import contextlib
import os
import socket
import subprocess
import sys
from pathlib import Path

import docker
import docker.errors
import gymnasium as gym
import numpy as np
import pytest

import envs  # noqa: F401
from contracts import process
from envs import RemoteCrashed, docker_pool
from envs.docker_pool import LABEL_POOL
from envs.vector import make_vector
from orchestrator.engine import LABEL_SLURM_JOB

pytestmark = pytest.mark.docker


def _pool_containers(client: docker.DockerClient, pool_id: str) -> list[object]:
    return list(client.containers.list(all=True, ignore_removed=True,
                                      filters={"label": f"{LABEL_POOL}={pool_id}"}))


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


_FOREIGN_OWNER = """
import os, sys, time
with open("/proc/sys/kernel/ns_last_pid", "w") as f:
    f.write(str(int(sys.argv[1]) - 1))
if os.fork() == 0:
    from envs.docker_pool import _owner
    print(_owner(), flush=True)
    time.sleep(120)
    os._exit(0)
os.wait()
"""


def test_a_new_pool_removes_remotes_of_ended_owners_only(
    docker_client: docker.DockerClient,
) -> None:
    """A new pool removes the remotes a killed process left, and leaves those of a live owner
    it cannot see (a process in another pid namespace sharing the engine: a pool in a
    container, a cluster job; its pid may be free in this one) and those of cluster jobs."""
    # a live pool's owner in a pid namespace of its own, with a pid that is free in this one
    free = next(p for p in range(int(Path("/proc/sys/kernel/pid_max").read_text()) - 1, 300, -1)
                if not Path(f"/proc/{p}").exists())
    other = subprocess.Popen(
        ["unshare", "--pid", "--fork", "--mount-proc", sys.executable, "-c", _FOREIGN_OWNER,
         str(free)], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
        cwd=Path(__file__).resolve().parents[3],
    )  # fmt: skip
    assert other.stdout is not None
    foreign = other.stdout.readline().strip()
    if not foreign:
        other.wait()
        pytest.skip(f"no pid namespace of its own here: {other.stderr.read()[-200:]}")
    try:
        _only_ended_owners_removed(docker_client, foreign, free)
    finally:
        other.kill()
        other.wait()


def _only_ended_owners_removed(client: docker.DockerClient, foreign: str, free: int) -> None:
    assert foreign.split(":")[1] != process.pid_namespace()
    assert foreign.split(":")[2] == str(free) and not Path(f"/proc/{free}").exists()
    child = subprocess.Popen([sys.executable, "-c", "import time; time.sleep(30)"])
    start = process.start_time(child.pid)
    child.kill()
    child.wait()
    ended = f"{socket.gethostname()}:{process.pid_namespace()}:{child.pid}:{start}"
    image = client.images.list(name="hlvs-runner/simulator")[0].id
    made = {}
    for name, owner, more in (("foreign", foreign, {}), ("ended", ended, {}),
                              ("job", ended, {LABEL_SLURM_JOB: "999999"})):
        made[name] = client.containers.create(
            image, command=["true"], name=f"hlvs-env-test-{name}-{os.getpid()}",
            labels={docker_pool.LABEL_PROJECT: "1", docker_pool.LABEL_ROLE: docker_pool.ROLE,
                    docker_pool.LABEL_POOL: f"test{name}{os.getpid()}",
                    docker_pool.LABEL_OWNER: owner, **more},
        )  # fmt: skip
    launcher = docker_pool.DockerLauncher(image=image, unix=False)
    try:
        role = f"{docker_pool.LABEL_ROLE}={docker_pool.ROLE}"
        left = {c.id for c in client.containers.list(all=True, filters={"label": role})}
        assert made["foreign"].id in left  # its owner runs, out of this process's sight
        assert made["ended"].id not in left  # its owner ended here
        assert made["job"].id in left  # a cluster job's: its epilog removes it
    finally:
        launcher.close()
        for container in made.values():
            with contextlib.suppress(docker.errors.NotFound):
                container.remove(force=True)
