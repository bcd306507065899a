"""A compressed tournament of real stub matches in Docker: pull, play in the window, deliver, table.

Two teams of one stub robot play each other twice; images are the project's local stub image
(pulled as local images), logs go to an S3 API server on 127.0.0.1. The schedule is compressed to
seconds: pulls 60 s before each stream, play right after the pull, delivery after the stream.
"""

from __future__ import annotations

import json
import shutil
from collections.abc import Iterator
from pathlib import Path

import boto3
import pytest

from orchestrator.config.credentials import load_credentials
from orchestrator.delivery.s3 import create_bucket
from orchestrator.schedule import Ledger, ScheduledMatchState, run_schedule, standings
from testkit.s3 import MotoServer

pytestmark = [pytest.mark.docker, pytest.mark.slow]

EXAMPLES = Path(__file__).resolve().parents[3] / "configs" / "examples" / "scrimmage_1v1"


@pytest.fixture(scope="module")
def s3() -> Iterator[MotoServer]:
    server = MotoServer.start()
    yield server
    server.stop()


def write_tournament(tmp: Path, s3: MotoServer) -> Path:
    names = {"ants": "team_red.json", "bees": "team_blue.json"}
    for name, source in names.items():
        team = json.loads((EXAMPLES / source).read_text())
        team["name"] = name
        (tmp / f"{name}.json").write_text(json.dumps(team))
        creds = {
            "type": "s3",
            "credentials": {
                "access_id": "test-id",
                "access_secret": "test-secret",
                "bucket": f"logs-{name}",
                "region": "us-east-1",
                "endpoint_url": s3.endpoint_url,
            },
        }
        path = tmp / f"{name}-credentials.json"
        path.write_text(json.dumps(creds))
        path.chmod(0o600)
        credentials = load_credentials(path)
        create_bucket(credentials)  # type: ignore[arg-type]
    schedule = tmp / "cup.yaml"
    schedule.write_text(
        """
name: compressed cup
output_dir: out
simulator_slots: 1
timing: {pull_lead_round_robin_s: 60, play_after_pull_s: 0.5, deliver_after_stream_s: 0.5,
         retry_s: 1}
game_defaults:
  stepping: lockstep
  seed: 7
  timing: {half_duration_s: 8, minimum_play_s: 0, wait_before_first_ready_s: 1,
           half_time_break_s: 1, grace_period_s: 3}
  limits: {cpus: 1, memory_gb: 1, pids: 256}
teams:
  - {name: ants, id: 1, config: ants.json, credentials: ants-credentials.json}
  - {name: bees, id: 2, config: bees.json, credentials: bees-credentials.json}
matches:
  - {id: m1, red: ants, blue: bees, stream_start: "+62s", stream_length_s: 2}
  - {id: m2, red: bees, blue: ants, stream_start: "+70s", stream_length_s: 2}
"""
    )
    return schedule


def test_compressed_tournament_of_real_matches(tmp_path: Path, s3: MotoServer) -> None:
    schedule = write_tournament(tmp_path, s3)
    state = tmp_path / "state.sqlite"
    assert run_schedule(schedule, state, exit_when_done=True, poll_s=0.5) == 0

    ledger = Ledger(state)
    rows = {row.id: row for row in ledger.rows()}
    assert {r.state for r in rows.values()} == {ScheduledMatchState.DELIVERED}, {
        r.id: (r.state, r.note) for r in rows.values()
    }
    for match_id, row in rows.items():
        history = {to: at for at, _, _, to, _ in ledger.history(match_id)}
        pulled = history["PULLED"]
        playing = history["PLAYING"]
        assert pulled <= playing < row.stream_start.isoformat(), (match_id, history)
        assert playing >= row.play_at.isoformat()
        assert history["DELIVERING"] >= row.deliver_at.isoformat()
        match_dir = tmp_path / "out" / match_id / "match"
        results = json.loads((match_dir / "results.json").read_text())
        report = json.loads((match_dir / "report.json").read_text())
        assert report["status"] == "success"
        assert row.result is not None
        assert row.result["score"] == {
            "red": results["score"]["red"],
            "blue": results["score"]["blue"],
        }

    client = boto3.client(
        "s3",
        endpoint_url=s3.endpoint_url,
        aws_access_key_id="test-id",
        aws_secret_access_key="test-secret",
        region_name="us-east-1",
    )
    for team in ("ants", "bees"):
        keys = [o["Key"] for o in client.list_objects_v2(Bucket=f"logs-{team}").get("Contents", [])]
        for match_id in ("m1", "m2"):
            assert f"{match_id}/{team}/MANIFEST.json" in keys, keys

    table = {s.team: s for s in standings(ledger.rows(), ["ants", "bees"])}
    goals = {"ants": 0, "bees": 0}
    for row in rows.values():
        assert row.result is not None
        goals[row.result["red_team"]] += row.result["score"]["red"]
        goals[row.result["blue_team"]] += row.result["score"]["blue"]
    assert table["ants"].played == table["bees"].played == 2
    assert table["ants"].goals_for == goals["ants"] == table["bees"].goals_against
    assert table["ants"].points + table["bees"].points in (4, 5, 6)  # 2 matches: 2-3 points each
    shutil.rmtree(tmp_path / "out", ignore_errors=True)
