"""The Slurm pool on a real Slurm cluster of five nodes on this machine (scripts/ensure-slurm.sh):
real matches side by side on different nodes, a team account's quota making its second match
wait with Slurm's reason, cancel while queued and while running."""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import time
from pathlib import Path

import pytest

from cluster import JobState, MatchJob
from cluster.slurm import SlurmPool

pytestmark = [pytest.mark.docker, pytest.mark.root, pytest.mark.slow]



def _job(tmp: Path, name: str, account: str) -> MatchJob:
    from orchestrator.match.scrimmage import ScrimmageRequest, write_files
    from orchestrator.project_images import project_image

    args = argparse.Namespace(
        red_image=None, blue_image=None, players=1, half_duration=4.0, ready_duration=1.0,
        wait_before_ready=1.0, minimum_play=0.0,
        grace=2.0, robot_command=None, match_id=f"slurm-{name}-{os.getpid()}", seed=7,
    )
    work = tmp / name
    game = write_files(ScrimmageRequest.from_options(args), work / "config",
                       stub_image=project_image("stub"))
    return MatchJob(match_id=args.match_id, game_path=game, work_dir=work, account=account)


def _wait(pool: SlurmPool, handle: str, states: set[JobState], timeout_s: float) -> JobState:
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        state = pool.status(handle).state
        if state in states:
            return state
        time.sleep(1.0)
    raise AssertionError(f"{handle} not in {states} after {timeout_s} s: {pool.status(handle)}")


def _sacct(conf: str, handle: str, field: str) -> str:
    job_id = handle.split(":")[1]
    out = subprocess.run(["sacct", "-n", "-X", "-P", "-j", job_id, "-o", field],
                         capture_output=True, text=True, env={**os.environ, "SLURM_CONF": conf},
                         check=True).stdout
    return out.strip()


def test_matches_in_parallel_quota_and_cancel(cluster: str, tmp_path: Path) -> None:
    pool = SlurmPool(slurm_conf=cluster, host_network=True)
    pool.ensure_account("team_a", max_running=1, max_queued=3)
    pool.ensure_account("team_b", max_running=1, max_queued=3)
    a1 = pool.submit(_job(tmp_path, "a1", "team_a"))
    b1 = pool.submit(_job(tmp_path, "b1", "team_b"))
    a2 = pool.submit(_job(tmp_path, "a2", "team_a"))
    assert pool.submit(_job(tmp_path, "a2", "team_a")) == a2  # resubmitting adopts the job
    _wait(pool, a1, {JobState.RUNNING}, 60)
    _wait(pool, b1, {JobState.RUNNING}, 60)
    waiting = pool.status(a2)
    assert waiting.state is JobState.PENDING
    assert "AssocGrpJobsLimit" in waiting.detail  # Slurm's reason: team_a already plays
    queue = {e.job_id: e for e in pool.queue()}
    assert queue[a2.split(":")[1]].reason == "AssocGrpJobsLimit"
    nodes = {queue[h.split(":")[1]].nodes for h in (a1, b1)}
    assert len(nodes) == 2  # dense placement: one match per node, side by side

    pool.cancel(a2)  # while queued: it never starts
    deadline = time.monotonic() + 60  # the accounting database learns of it a little later
    while "CANCELLED" not in _sacct(cluster, a2, "State") and time.monotonic() < deadline:
        time.sleep(1)
    assert "CANCELLED" in _sacct(cluster, a2, "State")
    assert not (pool.results_dir(a2) / "report.json").exists()

    time.sleep(8)  # a1's match is under way
    pool.cancel(a1)  # while running: a graceful stop with a complete report
    assert _wait(pool, a1, {JobState.FINISHED, JobState.LOST}, 300) is JobState.FINISHED
    report = json.loads((pool.results_dir(a1) / "report.json").read_text())
    assert report["status"] != "success" and report.get("failure_class") == "interrupted"

    assert _wait(pool, b1, {JobState.FINISHED, JobState.LOST}, 600) is JobState.FINISHED
    assert json.loads((pool.results_dir(b1) / "report.json").read_text())["status"] == "success"
    results = json.loads((pool.results_dir(b1) / "results.json").read_text())
    assert results["final_state"] == "FINISHED"
