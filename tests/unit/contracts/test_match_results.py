"""results.json and report.json: one typed contract, the league-facing keys unchanged."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from contracts.errors import ContractError, UnknownVersion
from contracts.match_results import (
    AdmissionRecord,
    Failure,
    FailureClass,
    Forfeit,
    LogFolderCopy,
    MatchLimits,
    MatchReport,
    MatchResults,
    NeededAvailable,
    RobotResult,
    Salvage,
    SalvagedRobot,
)
from contracts.sim_result import PlayRecord, SpoofingAttempt, SpoofingRecord

RESULT_KEYS = {
    "match_id", "seed", "warnings", "status", "failure", "forfeit", "final_state", "score",
    "winner", "events_summary", "play", "sim_time_ms", "real_time_factor", "robots", "spoofing",
    "limits", "versions", "timings_s", "bringup_s", "admission", "version",
}  # fmt: skip
ROBOT_KEYS = {
    "image", "digest", "image_error", "container", "startup_error", "exit_code", "oom_killed",
    "restarts", "exited_during_game", "cpu_peak_percent", "memory_peak_bytes", "sent_bytes",
    "received_bytes", "limits", "api", "log_folder", "spoofing_attempts",
}  # fmt: skip
LIMITS = MatchLimits(cpus=4.0, memory_gb=16.0, pids=1024, log_folder_gb=10.0,
                     team_api_mb_s=350.0, team_comm_mb_s=1.0, grace_period_s=5.0,
                     allow_internet=False, host_controls={"firewall": True})


def _played() -> MatchResults:
    return MatchResults(
        match_id="m1", seed=7, status="success", failure=None, warnings=("w",),
        final_state="FINISHED", score={"red": 2, "blue": 1}, winner="red",
        events_summary={"goal": 3},
        play=PlayRecord(halves_playing=(1, 2), both_halves_playing=True, playing_s=100.0,
                        kicks={"red": 2, "blue": 1}, shots={"red": 1, "blue": 0},
                        goals={"red": 2, "blue": 1}, own_goals={"red": 0, "blue": 0},
                        falls={"red": 0, "blue": 3}),
        sim_time_ms=60000, real_time_factor=0.98,
        robots={
            "red-1": RobotResult(
                image="team/red:1", digest="sha256:ab", container="m1-red-1", exit_code=0,
                cpu_peak_percent=12.5, memory_peak_bytes=1000, sent_bytes=10, received_bytes=20,
                limits={"nano_cpus": 4_000_000_000, "read_only_root": True, "cpuset": None,
                        "shaping_applied_ms": 1.5},
                api={"connects": 1}, log_folder=LogFolderCopy(
                    files=2, bytes=30, skipped=({"path": "x", "kind": "symlink"},),
                    skipped_count=1),
                spoofing_attempts=2),
            "blue-1": RobotResult(image=None, image_error="no image named for this player"),
        },
        spoofing=SpoofingRecord(total=2, attempts=(SpoofingAttempt(
            channel="api", sender="10.0.1.11", sender_robot="red-1", claimed="blue-1",
            message="connect", count=2),)),
        limits=LIMITS, versions={"hlvs-runner": "0.1", "simulator": {"mujoco": "3"}},
        timings_s={"playing": 60.0}, bringup_s=4.5, admission=AdmissionRecord(
            official=False, fits=True, host="this host", robots=2,
            cpus=NeededAvailable(needed=3.0, available=4.0),
            memory_gb=NeededAvailable(needed=4.0, available=15.5),
            simulator_cpu_shares=8192, warning=None),
    )  # fmt: skip


def _salvaged() -> MatchResults:
    return MatchResults(
        match_id="m2", status="failed",
        failure=Failure(failure_class=FailureClass.INTERRUPTED, cause="orchestrator gone"),
        salvaged=Salvage(robots={"red-1": SalvagedRobot(stdout=True), "blue-1": SalvagedRobot(
            log_folder=LogFolderCopy(files=1, bytes=3))}, public=("replay.hlvsrec",),
            errors=("blue-1: logs not saved: gone",)),
    )  # fmt: skip


@pytest.mark.parametrize("results", [_played(), _salvaged()], ids=["played", "salvaged"])
def test_results_round_trip(results: MatchResults, tmp_path: Path) -> None:
    path = results.write(tmp_path / "results.json")
    assert MatchResults.load(path) == results
    assert path.stat().st_mode & 0o777 == 0o600
    assert json.loads(path.read_text())["version"] == MatchResults.VERSION


def test_results_keep_the_league_facing_keys() -> None:
    data = json.loads(_played().to_json())
    assert set(data) == RESULT_KEYS
    assert set(data["robots"]["red-1"]) == ROBOT_KEYS
    assert data["failure"] is None and data["forfeit"] is None
    failed = json.loads(MatchResults(
        match_id="m", seed=1, status="failed", limits=LIMITS,
        failure=Failure(failure_class=FailureClass.SIMULATOR, cause="exited 1"),
        forfeit=None,
    ).to_json())  # fmt: skip
    assert failed["failure"] == {"class": "simulator", "cause": "exited 1"}
    salvaged = json.loads(_salvaged().to_json())
    assert set(salvaged) == {"version", "match_id", "status", "failure", "salvaged"}
    assert salvaged["salvaged"]["robots"] == {
        "red-1": {"stdout": True},
        "blue-1": {"log_folder": {"files": 1, "bytes": 3, "skipped": [], "skipped_count": 0}},
    }


def test_a_file_without_version_reads_as_version_1() -> None:
    data = json.loads(_played().to_json())
    del data["version"]
    assert MatchResults.from_dict(data) == _played()


@pytest.mark.parametrize(
    ("change", "message"),
    [
        (lambda d: d.update(version=2), "/version: match results version 2"),
        (lambda d: d["robots"]["red-1"].update(exit_code="0"),
         "/robots/red-1/exit_code: expected int"),
        (lambda d: d.update(failure={"class": "fire", "cause": "x"}, status="failed"),
         "/failure/class: expected one of"),
        (lambda d: d.update(final_sate="FINISHED"), "/final_sate: unknown field"),
        (lambda d: d.pop("match_id"), "/match_id: missing field"),
        (lambda d: d.update(status="failed"), "disagrees with failure"),
        (lambda d: d.pop("limits"), "seed and limits are required"),
    ],
)  # fmt: skip
def test_bad_results_name_the_file_and_field(change: object, message: str) -> None:
    data = json.loads(_played().to_json())
    change(data)  # type: ignore[operator]
    with pytest.raises(ContractError) as caught:
        MatchResults.from_dict(data, source="out/results.json")
    assert str(caught.value).startswith("out/results.json: ")
    assert message in str(caught.value)


def test_report_stays_the_teams_file(tmp_path: Path) -> None:
    assert MatchReport.of(None).to_json() == '{\n  "status": "success"\n}'
    failure = Failure(failure_class=FailureClass.TEAM_STARTUP, cause="no container")
    report = MatchReport.of(failure)
    assert json.loads(report.to_json()) == {
        "status": "failed", "failure_class": "team_startup", "cause": "no container"}
    path = report.write(tmp_path / "report.json")
    assert MatchReport.load(path) == report and MatchReport.load(path).failure == failure
    path.write_text(json.dumps({"status": "failed", "failure_class": "meteor", "cause": "x"}))
    with pytest.raises(ContractError, match=r"report.json: /failure_class: expected one of"):
        MatchReport.load(path)
    path.write_text(json.dumps({"status": "success", "version": 3}))
    with pytest.raises(UnknownVersion, match="match report version 3"):
        MatchReport.load(path)


def test_a_forfeit_is_written_as_before() -> None:
    forfeit = Forfeit(team="blue", winner="red", reason="no image", score={"red": 0, "blue": 0})
    data = json.loads(MatchResults(
        match_id="m", seed=1, status="success", failure=None, forfeit=forfeit, limits=LIMITS,
    ).to_json())  # fmt: skip
    assert data["forfeit"] == {"team": "blue", "winner": "red", "reason": "no image",
                               "score": {"red": 0, "blue": 0}}
