"""The remote part of ``hlvs bench envs --remotes N``: one remote over TCP and vector
environments over 1, 2, 4... remotes, all on containers of one pool started for the run.

Vector sizes are measured ``--repeats`` times, interleaved (1, 2, 4, 1, 2, 4...), so load from
other processes hits every size alike; each figure is the median of its runs. Besides steps per
second, each run reports where the CPU time of one environment step goes: in this process (the
client: the environment, the vector wrapper, encoding and decoding) and in the remotes'
containers (the world and the remote's side of the protocol, from the containers' CPU
accounting when this host's cgroup files show it).
"""

from __future__ import annotations

import os
import statistics
import time
from pathlib import Path
from typing import Any

CGROUP_CPU = (
    "/sys/fs/cgroup/cpuacct/docker/{id}/cpuacct.usage",  # cgroup v1, cgroupfs driver (ns)
    "/sys/fs/cgroup/system.slice/docker-{id}.scope/cpu.stat",  # cgroup v2, systemd driver
)


def _container_cpu_s(container_ids: list[str]) -> float | None:
    """CPU seconds the containers used so far, or None when the cgroup files are not here."""
    total = 0.0
    for cid in container_ids:
        for pattern in CGROUP_CPU:
            path = Path(pattern.format(id=cid))
            if not path.is_file():
                continue
            text = path.read_text()
            if path.name == "cpu.stat":
                usec = dict(line.split() for line in text.splitlines()).get("usage_usec", "0")
                total += int(usec) / 1e6
            else:
                total += int(text.strip()) / 1e9
            break
        else:
            return None
    return total


def _run(env: Any, batch: Any, containers: list[str], env_steps: int) -> dict[str, Any]:
    server0 = _container_cpu_s(containers)
    wall0, cpu0 = time.perf_counter(), time.process_time()
    for a in batch:
        env.step(a)
    wall, cpu = time.perf_counter() - wall0, time.process_time() - cpu0
    server1 = _container_cpu_s(containers)
    out: dict[str, Any] = {
        "env_steps_per_s": round(env_steps / wall, 1),
        "client_cpu_ms_per_step": round(cpu / env_steps * 1e3, 4),
        "remote_cpu_ms_per_step": None,
    }
    if server0 is not None and server1 is not None:
        out["remote_cpu_ms_per_step"] = round((server1 - server0) / env_steps * 1e3, 4)
    return out


def _env_run(
    address: str, container: list[str], steps: int, seed: int, steps_per_action: int
) -> dict[str, Any]:
    import gymnasium as gym

    import envs  # noqa: F401  (registers the ids)
    from benchmarks.envs_actions import actions

    env = gym.make("hlvs/Kick-v0", remotes=address, max_episode_s=3600.0,
                   steps_per_action=steps_per_action)  # fmt: skip
    try:
        env.reset(seed=seed)
        return _run(env, actions(steps, seed), container, steps)
    finally:
        env.close()


def _vector_run(
    addresses: list[str], containers: list[str], steps: int, seed: int, steps_per_action: int
) -> dict[str, Any]:
    import numpy as np

    from benchmarks.envs_actions import actions
    from envs.vector import make_vector

    size = len(addresses)
    vec = make_vector("hlvs/Kick-v0", remotes=",".join(addresses), max_episode_s=3600.0,
                      steps_per_action=steps_per_action)  # fmt: skip
    try:
        vec.reset(seed=seed)
        batch = np.repeat(actions(steps, seed)[:, None, :], size, axis=1)
        return _run(vec, batch, containers, steps * size)
    finally:
        vec.close()


def _median(runs: list[dict[str, Any]], key: str) -> float | None:
    values = [r[key] for r in runs if r[key] is not None]
    return round(statistics.median(values), 4) if values else None


def _summary(runs: list[dict[str, Any]]) -> dict[str, Any]:
    return {
        "env_steps_per_s": _median(runs, "env_steps_per_s"),
        "client_cpu_ms_per_step": _median(runs, "client_cpu_ms_per_step"),
        "remote_cpu_ms_per_step": _median(runs, "remote_cpu_ms_per_step"),
        "runs_env_steps_per_s": [r["env_steps_per_s"] for r in runs],
    }


def bench_remotes(
    *, remotes: int, sizes: list[int], steps: int, seed: int, repeats: int = 1,
    steps_per_action: int = 1,
) -> dict[str, Any]:
    from envs.docker_pool import DockerLauncher
    from envs.remote_pool import RemotePool

    count = max([remotes, *sizes])
    load_before = os.getloadavg()
    started = time.perf_counter()
    pool = RemotePool.open(count)
    start_s = time.perf_counter() - started
    assert isinstance(pool.launcher, DockerLauncher)
    containers = list(pool.launcher.containers)
    try:
        urls = [str(a) for a in pool.addresses]
        one = _env_run(urls[0], containers[:1], steps, seed, steps_per_action)
        runs: dict[int, list[dict[str, Any]]] = {k: [] for k in sizes}
        for _ in range(repeats):
            for k in sizes:
                runs[k].append(
                    _vector_run(urls[:k], containers[:k], steps, seed, steps_per_action)
                )
    finally:
        pool.close()
    vector = {str(k): _summary(v) for k, v in runs.items()}
    rates = {k: v["env_steps_per_s"] for k, v in vector.items()}
    out: dict[str, Any] = {
        "remote_tcp": {**one, "steps": steps},
        "steps_per_action": steps_per_action,
        "vector_env_steps_per_s": rates,
        "vector": vector,
        "vector_repeats": repeats,
        "transport": "unix" if getattr(pool.addresses[0], "path", None) else "tcp",
        "remotes_started": count,
        "remotes_start_s": round(start_s, 2),
        "load_average": {"before": [round(v, 2) for v in load_before],
                         "after": [round(v, 2) for v in os.getloadavg()]},  # fmt: skip
        "cpus": os.cpu_count(),
    }
    if rates.get("1") and rates.get("2"):
        out["scaling_2_over_1"] = round(rates["2"] / rates["1"], 3)
    return out
