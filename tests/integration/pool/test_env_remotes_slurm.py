"""``remotes="slurm:N"``: environment remotes allocated from the Slurm cluster on this machine
(one job per remote running the simulator image on a node), health-checked, diagnosed and
replaced after a crash, and released at close or when the client process dies (its lease
expires): no job and no container left."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import docker
import numpy as np
import pytest

import envs  # noqa: F401
from envs import RemoteCrashed
from envs.vector import make_vector
from orchestrator.engine import LABEL_SLURM_JOB

pytestmark = [pytest.mark.docker, pytest.mark.root, pytest.mark.slow]


def _slurm(conf: str, *args: str) -> str:
    return subprocess.run(list(args), capture_output=True, text=True, check=True,
                          env={**os.environ, "SLURM_CONF": conf}).stdout  # fmt: skip


def _listed(conf: str, job_ids: list[str]) -> list[str]:
    out = _slurm(conf, "squeue", "-h", "-j", ",".join(job_ids), "-o", "%i")
    return [line.strip() for line in out.splitlines() if line.strip() in job_ids]


def _containers(client: docker.DockerClient, job_ids: list[str]) -> list[str]:
    return [str(c.name) for job in job_ids for c in client.containers.list(
        all=True, ignore_removed=True, filters={"label": f"{LABEL_SLURM_JOB}={job}"})]  # fmt: skip


def test_two_remotes_on_the_cluster_step_are_replaced_and_released(
    cluster: str, docker_client: docker.DockerClient
) -> None:
    vec = make_vector("hlvs/Kick-v0", remotes=f"slurm:2?conf={cluster}&timeout=240")
    launcher = vec.pool.launcher
    jobs = [job.job_id for job in launcher.jobs]
    try:
        nodes = {job.node for job in launcher.jobs}
        assert len(nodes) == 2 and all(n.startswith("n") for n in nodes), nodes  # two nodes
        running = _slurm(cluster, "squeue", "-h", "-j", ",".join(jobs), "-o", "%T")
        assert running.split() == ["RUNNING", "RUNNING"]
        assert len(_containers(docker_client, jobs)) == 2  # labelled with their jobs
        obs, _ = vec.reset(seed=5)
        for _ in range(25):
            obs, rewards, _, _, infos = vec.step(np.zeros((2, 20), np.float32))
        assert list(infos["sim_time_ms"]) == [200, 200] and rewards.shape == (2,)
        assert not np.array_equal(obs["joints"][0], obs["joints"][1])  # seeds 5 and 6

        # remote 1's container dies: the step names the job, the node and the exit code
        env = vec.envs[1]
        docker_client.containers.get(_containers(docker_client, [jobs[1]])[0]).kill()
        with pytest.raises(RemoteCrashed) as crashed:
            for _ in range(50):
                env.step(np.zeros(20, np.float32))
        assert f"Slurm job {jobs[1]} on n" in crashed.value.cause
        assert "exited with code 137" in crashed.value.cause
        env.reset(seed=6)  # a new job takes its place
        replacement = launcher.jobs[1].job_id
        assert replacement not in jobs and _listed(cluster, [jobs[1]]) == []
        *_, info = env.step(np.zeros(20, np.float32))
        assert info["sim_time_ms"] == 8
        jobs.append(replacement)
    finally:
        vec.close()
    assert _listed(cluster, jobs) == []  # close waits until Slurm has ended them
    assert _containers(docker_client, jobs) == []
    out = _slurm(cluster, "sacct", "-n", "-X", "-P", "-j", ",".join(jobs), "-o", "JobID,State")
    states = dict(line.split("|") for line in out.splitlines())
    assert states[jobs[0]].startswith("CANCELLED") and states[jobs[2]].startswith("CANCELLED")
    assert states[jobs[1]].split()[0] in ("CANCELLED", "FAILED"), states  # replaced: scancel


def test_a_dead_client_lets_its_remote_go_when_the_lease_expires(
    cluster: str, docker_client: docker.DockerClient, tmp_path: Path
) -> None:
    code = (  # its job folder (kept: nobody closed the pool) goes to tmp_path
        "import gymnasium as gym, envs, sys\n"
        f"env = gym.make('hlvs/Kick-v0', remotes='slurm:1?conf={cluster}&lease=4&dir={tmp_path}')\n"
        "env.reset(seed=1)\n"
        "print(env.unwrapped._owner.launcher.jobs[0].job_id, flush=True)\n"
        "sys.stdin.read()\n"
    )
    child = subprocess.Popen([sys.executable, "-c", code], stdin=subprocess.PIPE,
                             stdout=subprocess.PIPE, text=True)  # fmt: skip
    try:
        assert child.stdout is not None
        job = child.stdout.readline().strip()
        assert job.isdigit(), job
        assert _listed(cluster, [job]) == [job] and len(_containers(docker_client, [job])) == 1
        child.send_signal(signal.SIGKILL)  # no close(), no atexit
        child.wait(10)
        deadline = time.monotonic() + 40
        while _listed(cluster, [job]) and time.monotonic() < deadline:
            time.sleep(0.5)
        assert _listed(cluster, [job]) == []
        assert _containers(docker_client, [job]) == []
        state = _slurm(cluster, "sacct", "-n", "-X", "-P", "-j", job, "-o", "State,ExitCode")
        assert state.strip() == "COMPLETED|0:0", state  # the job released it by itself
    finally:
        if child.poll() is None:
            child.kill()
