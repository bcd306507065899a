"""Nodes die mid-match: the test match is requeued by Slurm and played to its end on another
node; the official match is not requeued and waits for the operator.

What "the node died" means on this one-machine cluster: every node shares the host's kernel and
Docker engine, so ``kill -9`` of a node's ``slurmd`` alone leaves the job's processes and the
match's containers running (a dead VM would take them with it). The test therefore kills, as a
dead node would, the node's ``slurmd`` (Slurm's own failure detection then marks the node DOWN
after ``SlurmdTimeout`` and requeues the job), the job's processes on that node (its
``slurmstepd`` and the ``hlvs match`` under it) and the match's containers. The requeued job
on another node salvages what the dead run left (``hlvs cleanup --match``), keeps that
attempt's files in ``attempt-1/`` and plays the match from the start. The node is restarted
and resumed afterwards."""

from __future__ import annotations

import argparse
import json
import os
import signal
import subprocess
import sys
import time
from collections.abc import Iterator
from pathlib import Path

import pytest

from cluster import JobState, MatchJob
from cluster.slurm import SlurmPool

pytestmark = [pytest.mark.docker, pytest.mark.root, pytest.mark.slow]

SLURM_DIR = Path("/var/lib/hlvs/slurm")


def _job(tmp: Path, match_id: str, *, requeue: bool) -> MatchJob:
    from orchestrator.match.scrimmage import ScrimmageRequest, write_files
    from orchestrator.project_images import project_image

    args = argparse.Namespace(
        red_image=None, blue_image=None, players=1, half_duration=6.0, ready_duration=1.0,
        minimum_play=0.0,
        wait_before_ready=1.0, grace=2.0, robot_command=None, match_id=match_id, seed=7,
    )
    game = write_files(ScrimmageRequest.from_options(args), tmp / "config",
                       stub_image=project_image("stub"))
    return MatchJob(match_id=match_id, game_path=game, work_dir=tmp / "work", requeue=requeue)


def _env(conf: str) -> dict[str, str]:
    return {**os.environ, "SLURM_CONF": conf}


def _show_job(conf: str, job_id: str) -> dict[str, str]:
    text = subprocess.run(["scontrol", "show", "job", "-o", job_id], capture_output=True,
                          text=True, env=_env(conf), check=False).stdout
    return dict(f.split("=", 1) for f in text.split() if "=" in f)


def _job_pids(job_id: str) -> list[int]:
    """The job's processes on this machine: its slurmstepd and everything that carries the
    job's id in its environment."""
    pids = []
    for entry in Path("/proc").iterdir():
        if not entry.name.isdigit():
            continue
        try:
            cmdline = (entry / "cmdline").read_bytes()
            environ = (entry / "environ").read_bytes()
        except OSError:
            continue
        if cmdline.startswith(f"slurmstepd: [{job_id}.".encode()) or \
                f"SLURM_JOB_ID={job_id}\0".encode() in environ:
            pids.append(int(entry.name))
    return pids


@pytest.fixture()
def node_restarter(cluster: str) -> Iterator[list[str]]:
    killed: list[str] = []
    yield killed
    for node in killed:  # bring the node back: slurmd in its namespace, then resume it
        subprocess.run(["nsenter", f"--net=/run/netns/hlvs-{node}", "slurmd", "-f", cluster,
                        "-N", node], env=_env(cluster), check=True, timeout=60)
        deadline = time.monotonic() + 120
        while time.monotonic() < deadline:
            subprocess.run(["scontrol", "update", f"nodename={node}", "state=resume"],
                           env=_env(cluster), capture_output=True, check=False)
            state = subprocess.run(["sinfo", "-h", "-n", node, "-o", "%T"], env=_env(cluster),
                                   capture_output=True, text=True, check=False).stdout.strip()
            if state in ("idle", "allocated", "mixed"):
                break
            time.sleep(2)
        else:
            pytest.fail(f"node {node} did not come back ({state})")


def test_node_killed_mid_match_requeues_and_completes(
    cluster: str, tmp_path: Path, node_restarter: list[str],
) -> None:
    """Two matches on two nodes that both die: the test match (``--requeue``) is played again
    on the third node; the official one (``--no-requeue``) ends as a node failure and waits
    for the operator, whose ``hlvs cleanup --match`` salvages what it left."""
    import docker

    pool = SlurmPool(slurm_conf=cluster, host_network=True)
    test_id, official_id = f"slurm-fail-{os.getpid()}", f"slurm-official-{os.getpid()}"
    handle = pool.submit(_job(tmp_path / "test", test_id, requeue=True))
    official = pool.submit(_job(tmp_path / "official", official_id, requeue=False))
    job_id, official_job = pool.job_id(handle), pool.job_id(official)
    client = docker.from_env()
    for h, match_id in ((handle, test_id), (official, official_id)):
        deadline = time.monotonic() + 180
        while time.monotonic() < deadline:  # wait until each match is under way on its node
            if pool.status(h).state is JobState.RUNNING and client.containers.list(
                    filters={"label": f"org.hlvs-runner.match={match_id}"}):
                break
            time.sleep(1)
        else:
            pytest.fail(f"{h} never ran its match: {pool.status(h)}")
    time.sleep(3)
    node = _show_job(cluster, job_id)["NodeList"]
    official_node = _show_job(cluster, official_job)["NodeList"]
    assert node != official_node

    # both nodes die: their slurmd, the jobs' processes on them and the matches' containers
    for dead, job, match_id in ((node, job_id, test_id),
                                (official_node, official_job, official_id)):
        os.kill(int((SLURM_DIR / f"slurmd-{dead}.pid").read_text()), signal.SIGKILL)
        node_restarter.append(dead)
        for pid in _job_pids(job):
            try:
                os.kill(pid, signal.SIGKILL)
            except ProcessLookupError:
                pass
        for container in client.containers.list(
                filters={"label": f"org.hlvs-runner.match={match_id}"}):
            container.kill()

    deadline = time.monotonic() + 240  # SlurmdTimeout=10: DOWN in about 25 s, then requeued
    while time.monotonic() < deadline:
        if int(_show_job(cluster, job_id).get("Restarts", "0")) >= 1:
            break
        time.sleep(2)
    else:
        pytest.fail(f"job {job_id} was not requeued: {_show_job(cluster, job_id)}")
    state = subprocess.run(["sinfo", "-h", "-n", node, "-o", "%T"], env=_env(cluster),
                           capture_output=True, text=True, check=False).stdout.strip()
    assert state.startswith("down"), state  # Slurm saw the node die

    # the official match: not requeued, lost with Slurm's NODE_FAIL, for the operator
    # (LOST without a report, or already salvaged by any 'hlvs cleanup' run on this machine,
    # which takes every match whose orchestrator is gone)
    if _wait_end(pool, official, 120) is JobState.LOST:
        assert "NODE_FAIL" in pool.status(official).detail
    assert _sacct_field(cluster, official_job, "State") == "NODE_FAIL"
    assert _show_job(cluster, official_job).get("Restarts", "0") == "0"
    cleanup = subprocess.run(
        [sys.executable, "-m", "hlvs", "cleanup", "--match", official_id],
        capture_output=True, text=True, timeout=300, check=False)
    assert cleanup.returncode == 0, cleanup.stderr[-2000:]
    kept = json.loads((pool.results_dir(official) / "report.json").read_text())
    assert kept.get("failure_class") == "interrupted", kept  # its logs so far, salvaged

    # the test match: played again on the live node
    assert _wait_end(pool, handle, 600) is JobState.FINISHED
    report = json.loads((pool.results_dir(handle) / "report.json").read_text())
    assert report["status"] == "success", report
    results = json.loads((pool.results_dir(handle) / "results.json").read_text())
    assert results["final_state"] == "FINISHED"
    second_node = _show_job(cluster, job_id).get("NodeList") or _sacct_node(cluster, job_id)
    assert second_node not in (node, official_node)  # played again on a live node
    first = pool.results_dir(handle) / "attempt-1"  # the dead run's salvaged files, kept
    salvaged = json.loads((first / "report.json").read_text())
    assert salvaged.get("failure_class") == "interrupted", salvaged
    assert sorted(p.name for p in first.iterdir()) != ["report.json"], list(first.iterdir())
    for match_id in (test_id, official_id):  # nothing of any run is left
        assert client.containers.list(all=True, filters={
            "label": f"org.hlvs-runner.match={match_id}"}) == []


def _sacct_node(conf: str, job_id: str) -> str:
    return _sacct_field(conf, job_id, "NodeList")


def _sacct_field(conf: str, job_id: str, field: str) -> str:
    return subprocess.run(["sacct", "-n", "-X", "-P", "-j", job_id, "-o", field],
                          capture_output=True, text=True, env=_env(conf),
                          check=False).stdout.strip()


def _wait_end(pool: SlurmPool, handle: str, timeout_s: float) -> JobState:
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        state = pool.status(handle).state
        if state in (JobState.FINISHED, JobState.LOST):
            return state
        time.sleep(2)
    raise AssertionError(f"{handle} did not end: {pool.status(handle)}")
