"""A compressed tournament of real stub matches in Docker: pull, play in the window, deliver, table.

Four teams of one stub robot play two matches; images are the project's local stub image
(pulled as local images). Three teams' logs go to an S3 API server on 127.0.0.1; the fourth
team's SFTP server is down (nothing listens on its port): its logs are retried, then failed with
the cause, and never shown delivered. The schedule is compressed to seconds: pulls 60 s before
each stream, play right after the pull, delivery after the stream. m2 waits for the one
simulator slot while m1 plays (about 40 s on a quiet machine, 80 s on a loaded one); its window
closes at its stream start, 88 s after m1's.
"""

from __future__ import annotations

import json
import shutil
import threading
import time
from collections.abc import Callable, Iterator
from pathlib import Path

import boto3
import pytest

from orchestrator.config.credentials import load_credentials
from orchestrator.config.schedule_check import check_schedule
from orchestrator.delivery import pending_status
from orchestrator.delivery.s3 import create_bucket
from testkit.s3 import MotoServer
from testkit.sftp import free_port
from tournament import Ledger, ScheduledMatchState, run_schedule, standings
from tournament.controls import abort, reschedule
from tournament.overview import status_lines, tournament_overview

pytestmark = [pytest.mark.docker, pytest.mark.slow]

HOST_KEY = "ssh-ed25519 AAAAC3NzaC1lZDI1NTE5AAAAILxD7/6Y8WqDP6ruY81+KhRD3hE1yx9rKAmI0vF5eFKN"
EXAMPLES = Path(__file__).resolve().parents[3] / "configs" / "examples" / "scrimmage_1v1"


@pytest.fixture(scope="module")
def s3() -> Iterator[MotoServer]:
    server = MotoServer.start()
    yield server
    server.stop()


def _s3_credentials(tmp: Path, name: str, s3: MotoServer) -> Path:
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
    create_bucket(load_credentials(path))  # type: ignore[arg-type]
    return path


def _dead_sftp_credentials(tmp: Path, name: str) -> Path:
    """An SFTP target on a port where nothing listens (the team's server is down)."""
    creds = {
        "type": "sftp",
        "credentials": {
            "hostname": "127.0.0.1",
            "port": free_port(),
            "username": "hlvs",
            "password": "change-me",
            "path": "hlvs-logs",
            "host_key": HOST_KEY,
        },
    }
    path = tmp / f"{name}-credentials.json"
    path.write_text(json.dumps(creds))
    path.chmod(0o600)
    return path


def write_tournament(tmp: Path, s3: MotoServer) -> Path:
    """Four teams, two matches: cats' log server is down, the others deliver to S3."""
    sources = {"ants": "team_red.json", "bees": "team_red.json", "cats": "team_blue.json",
               "dogs": "team_blue.json"}
    for name, source in sources.items():
        team = json.loads((EXAMPLES / source).read_text())
        team["name"] = name
        (tmp / f"{name}.json").write_text(json.dumps(team))
        if name == "cats":
            _dead_sftp_credentials(tmp, name)
        else:
            _s3_credentials(tmp, name, s3)
    schedule = tmp / "cup.yaml"
    schedule.write_text(
        """
name: compressed cup
output_dir: out
simulator_slots: 1
timing: {pull_lead_round_robin_s: 60, play_after_pull_s: 0.5, deliver_after_stream_s: 0.5,
         retry_s: 1, delivery_attempts: 2}
game_defaults:
  stepping: lockstep
  seed: 7
  timing: {half_duration_s: 16, ready_duration_s: 1, wait_before_first_ready_s: 1,
           half_time_break_s: 1, grace_period_s: 3}
  limits: {cpus: 1, memory_gb: 1, pids: 256}
teams:
  - {name: ants, id: 1, config: ants.json, credentials: ants-credentials.json}
  - {name: bees, id: 2, config: bees.json, credentials: bees-credentials.json}
  - {name: cats, id: 3, config: cats.json, credentials: cats-credentials.json}
  - {name: dogs, id: 4, config: dogs.json, credentials: dogs-credentials.json}
matches:
  - {id: m1, red: ants, blue: cats, stream_start: "+62s", stream_length_s: 2}
  - {id: m2, red: bees, blue: dogs, stream_start: "+150s", stream_length_s: 2}
"""
    )
    return schedule


def test_compressed_tournament_of_real_matches(tmp_path: Path, s3: MotoServer) -> None:
    schedule = write_tournament(tmp_path, s3)
    assert check_schedule(schedule) == []  # what hlvs check and hlvs schedule run accept
    state = tmp_path / "state.sqlite"
    assert run_schedule(schedule, state, exit_when_done=True, poll_s=0.5) == 0

    ledger = Ledger(state)
    rows = {row.id: row for row in ledger.rows()}
    states = {r.id: (r.state, r.note) for r in rows.values()}
    assert rows["m2"].state is ScheduledMatchState.DELIVERED, states
    assert rows["m1"].state is ScheduledMatchState.LOGS_FAILED, states
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
        assert row.state.played and row.result is not None
        assert row.result["score"] == {
            "red": results["score"]["red"],
            "blue": results["score"]["blue"],
        }

    # cats' target is down: failed with the cause, retried once, never delivered
    logs = {entry.team: entry for entry in rows["m1"].logs}
    assert logs["cats"].state == "failed" and logs["cats"].attempts == 2, logs
    assert logs["cats"].cause.startswith("unreachable: cannot connect"), logs
    assert logs["ants"].state == "delivered" and logs["ants"].attempts == 1, logs
    notes = [note for _, _, _, _, note in ledger.history("m1")]
    assert any("cats retrying (unreachable" in note for note in notes), notes
    assert not any(to == "DELIVERED" for _, _, _, to, _ in ledger.history("m1"))
    assert not any("cats delivered" in note for note in notes), notes
    assert {e.team: e.state for e in rows["m2"].logs} == {"bees": "delivered",
                                                          "dogs": "delivered"}
    waiting = [s for s in pending_status(tmp_path / "out" / "log-store")]
    assert [(s.match_id, s.team) for s in waiting] == [("compressed-cup-m1", "cats")]
    status = "\n".join(status_lines(ledger))
    assert "cats failed after 2 attempts (unreachable: cannot connect" in status, status

    client = boto3.client(
        "s3",
        endpoint_url=s3.endpoint_url,
        aws_access_key_id="test-id",
        aws_secret_access_key="test-secret",
        region_name="us-east-1",
    )
    for team, match_id in (("ants", "m1"), ("bees", "m2"), ("dogs", "m2")):
        keys = [o["Key"] for o in client.list_objects_v2(Bucket=f"logs-{team}").get("Contents", [])]
        assert f"compressed-cup-{match_id}/{team}/MANIFEST.json" in keys, keys

    # the operator's overview: each played match links its replay (hlvs match's public/)
    view = tournament_overview(ledger)
    for match in view["matches"]:
        assert match["watch"] == {
            "replay": f"/watch/tournament/replay/{match['id']}?red={match['red']}"
                      f"&blue={match['blue']}"}, match
        assert match["played"] and match["logs_delivered"] is (match["id"] == "m2")

    table = {s.team: s for s in standings(ledger.rows(), ["ants", "bees", "cats", "dogs"])}
    for row in rows.values():
        assert row.result is not None
        red, blue = table[row.result["red_team"]], table[row.result["blue_team"]]
        assert red.played == blue.played == 1
        assert red.goals_for == row.result["score"]["red"] == blue.goals_against
    shutil.rmtree(tmp_path / "out", ignore_errors=True)


ABORT_CUP = """
name: abort cup
output_dir: out
timing: {pull_lead_round_robin_s: 600, play_after_pull_s: 0.2}
game_defaults:
  stepping: lockstep
  seed: 7
  timing: {half_duration_s: 16, ready_duration_s: 1, wait_before_first_ready_s: 1,
           half_time_break_s: 1, grace_period_s: 2}
  limits: {cpus: 1, memory_gb: 1, pids: 256}
teams:
  - {name: ants, id: 1, config: ants.json}
  - {name: bees, id: 2, config: bees.json}
matches:
  - {id: a1, red: ants, blue: bees, stream_start: "+590s"}
"""


def _until(predicate: Callable[[], bool], what: str, timeout_s: float = 120.0) -> None:
    deadline = time.monotonic() + timeout_s
    while not predicate():
        assert time.monotonic() < deadline, f"timed out waiting for {what}"
        time.sleep(0.2)


def test_abort_a_real_match_then_play_it_again_in_a_new_attempt_folder(tmp_path: Path) -> None:
    """hlvs match stops on the abort (SIGTERM, its grace), the match is ABORTED with the reason;
    rescheduled, it plays again and the first attempt's files stay in attempt-1/."""
    for name, source in (("ants", "team_red.json"), ("bees", "team_blue.json")):
        team = json.loads((EXAMPLES / source).read_text())
        team["name"] = name
        (tmp_path / f"{name}.json").write_text(json.dumps(team))
    schedule = tmp_path / "cup.yaml"
    schedule.write_text(ABORT_CUP)
    state = tmp_path / "state.sqlite"
    out = tmp_path / "out" / "a1" / "match"
    stop = threading.Event()
    runner = threading.Thread(target=run_schedule, args=(schedule, state),
                              kwargs={"poll_s": 0.2, "stop": stop})
    runner.start()
    try:
        _until(lambda: (out / "simulator" / "match_spec.json").is_file(), "the match to start")
        ledger = Ledger(state)
        abort(ledger, "a1", reason="the field lights went out", grace_s=60)
        _until(lambda: ledger.row("a1").state is ScheduledMatchState.ABORTED, "the abort")
        row = ledger.row("a1")
        assert row.note == "aborted by the operator: the field lights went out"
        assert row.result is not None and row.result["status"] != "success"
        report = json.loads((out / "report.json").read_text())  # stopped and collected
        assert report["status"] == "failed", report
        reschedule(ledger, "a1", at="+300s")
        _until(lambda: (out / "attempt-1" / "report.json").is_file()
               and (out / "simulator" / "match_spec.json").is_file(), "the second attempt")
        abort(ledger, "a1", reason="again", grace_s=60)
        _until(lambda: ledger.row("a1").state is ScheduledMatchState.ABORTED, "the 2nd abort")
    finally:
        stop.set()
        runner.join(timeout=120)
    assert ledger.row("a1").attempts == 2
    assert json.loads((out / "attempt-1" / "report.json").read_text()) == report
    assert (out / "report.json").is_file() and not (out / "attempt-2").exists()
    shutil.rmtree(tmp_path / "out", ignore_errors=True)
