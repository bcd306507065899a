"""The scheduler's restart test with the Slurm pool: the scheduler is killed (SIGKILL) while its
match runs as a Slurm job; the job goes on without it, the restarted scheduler adopts it, and
every match is played exactly once (one Slurm job each) and delivered. Short real stub matches
(1 v 1, 4 s halves) on the five-node cluster of scripts/ensure-slurm.sh."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from tournament import Ledger, ScheduledMatchState

pytestmark = [pytest.mark.docker, pytest.mark.root, pytest.mark.slow]

ROOT = Path(__file__).resolve().parents[3]
EXAMPLES = ROOT / "configs" / "examples" / "scrimmage_1v1"
SERVICES = "tests.integration.pool.slurm_services:SlurmTestServices"
HOST_KEY = "ssh-ed25519 AAAAC3NzaC1lZDI1NTE5AAAAILxD7/6Y8WqDP6ruY81+KhRD3hE1yx9rKAmI0vF5eFKN"


def _schedule(tmp: Path, conf: str, ids: tuple[str, str]) -> Path:
    for name, source in (("ants", "team_red.json"), ("bees", "team_blue.json")):
        team = json.loads((EXAMPLES / source).read_text())
        team["name"] = name
        (tmp / f"{name}.json").write_text(json.dumps(team))
        # a log target, as the schedule check asks of every team; the test's services record
        # the delivery without connecting to it
        creds = tmp / f"{name}-credentials.json"
        creds.write_text(json.dumps({"type": "sftp", "credentials": {
            "hostname": "127.0.0.1", "port": 2222, "username": "hlvs", "password": "change-me",
            "path": "hlvs-logs", "host_key": HOST_KEY}}))
        creds.chmod(0o600)
    path = tmp / "cup.yaml"
    path.write_text(f"""
name: slurm cup
output_dir: out
simulator_slots: 2
pool: {{kind: slurm, slurm_conf: {conf}}}
timing: {{pull_lead_round_robin_s: 60, play_after_pull_s: 0.5, deliver_after_stream_s: 0.5,
         retry_s: 1}}
game_defaults:
  stepping: lockstep
  seed: 7
  timing: {{half_duration_s: 16, ready_duration_s: 1, wait_before_first_ready_s: 1,
           half_time_break_s: 1, grace_period_s: 2}}
  limits: {{cpus: 1, memory_gb: 1, pids: 256}}
teams:
  - {{name: ants, id: 1, config: ants.json, credentials: ants-credentials.json}}
  - {{name: bees, id: 2, config: bees.json, credentials: bees-credentials.json}}
matches:
  - {{id: {ids[0]}, red: ants, blue: bees, stream_start: "+62s", stream_length_s: 1}}
  - {{id: {ids[1]}, red: bees, blue: ants, stream_start: "+64s", stream_length_s: 1}}
""")
    return path


def _job_state(conf: str, job_id: str) -> str:
    out = subprocess.run(["squeue", "-h", "-j", job_id, "-o", "%T"], capture_output=True,
                         text=True, env={**os.environ, "SLURM_CONF": conf}, check=False).stdout
    return out.strip()


def test_scheduler_killed_mid_match_then_restarted_plays_each_match_once(
    cluster: str, tmp_path: Path,
) -> None:
    ids = (f"sl{os.getpid()}a", f"sl{os.getpid()}b")
    path = _schedule(tmp_path, cluster, ids)
    state = tmp_path / "state.sqlite"
    cmd = [sys.executable, "-m", "hlvs.cli", "schedule", "run", str(path), "--state",
           str(state), "--exit-when-done", "--services", SERVICES]
    first_log = (tmp_path / "first-scheduler.log").open("w")
    first = subprocess.Popen(cmd, stdout=first_log, stderr=subprocess.STDOUT)
    record = tmp_path / "out" / ids[0] / "match" / "slurm.json"
    deadline = time.monotonic() + 180
    job_id, running = "", False
    while time.monotonic() < deadline and first.poll() is None:  # until its first match runs
        if record.is_file():
            job_id = json.loads(record.read_text())["job_id"]
            if _job_state(cluster, job_id) == "RUNNING":
                running = True
                break
        time.sleep(0.5)
    if not running:
        first.kill()
        first.wait()
        said = (tmp_path / "first-scheduler.log").read_text()[-3000:]
        pytest.fail(f"the first match never ran in Slurm (job {job_id or 'not submitted'}); "
                    f"the scheduler said:\n{said}")
    first.send_signal(signal.SIGKILL)
    first.wait()
    assert Ledger(state).row(ids[0]).state is ScheduledMatchState.PLAYING
    time.sleep(2)
    assert _job_state(cluster, job_id) == "RUNNING"  # the match goes on without the scheduler

    second = subprocess.run(cmd, capture_output=True, text=True, timeout=600)
    assert second.returncode == 0, second.stderr[-3000:]
    ledger = Ledger(state)
    log = (tmp_path / "out" / "services.log").read_text().split()
    for match_id in ids:
        row = ledger.row(match_id)
        assert row.state is ScheduledMatchState.DELIVERED, (row.state, row.note)
        match_dir = tmp_path / "out" / match_id / "match"
        jobs = sorted(p.name for p in match_dir.glob("slurm-*.out"))
        assert len(jobs) == 1, jobs  # one Slurm job per match, across both schedulers
        report = json.loads((match_dir / "report.json").read_text())
        assert report["status"] == "success", report
        results = json.loads((match_dir / "results.json").read_text())
        assert row.result is not None
        assert row.result["score"] == results["score"]
        assert log.count(match_id) >= 3  # pull, play-start, ..., deliver recorded
    assert (tmp_path / "out" / ids[0] / "match" / f"slurm-{job_id}.out").is_file()
    history = [h for h in ledger.history(ids[0]) if "interrupted" in h[4]]
    assert history, "the interrupted play step was not recorded as such"
