"""A short match with test robots in real containers: outputs, environment, isolation."""

from __future__ import annotations

import json

import pytest

from tests.integration.match.conftest import MatchFactory

pytestmark = [pytest.mark.docker, pytest.mark.root]


def test_match_writes_complete_results_and_each_robot_sees_its_environment(
    play: MatchFactory,
) -> None:
    outcome = play(red=[["env"], ["env"]], blue=[["env"]], sim=("4",))
    out = outcome.out_dir
    report = json.loads((out / "report.json").read_text())
    assert report == {"status": "success"}, report
    results = json.loads((out / "results.json").read_text())
    assert results["score"] == {"red": 1, "blue": 0}
    assert set(results["robots"]) == {"red-1", "red-2", "blue-1"}
    for name in ("replay.hlvsrec", "referee.log", "gamecontroller.log", "sim_result.json"):
        assert (out / "public" / name).is_file(), name
    env = json.loads((out / "teams/red/2/robocup-logs/env.json").read_text())["env"]
    sim_ip = env["ROBOCUP_MIRROR_SERVER_IP"]
    assert env["ROBOCUP_ROBOT_ID"] == "2"
    assert env["ROBOCUP_TEAM_COLOR"] == "red"
    assert env["ROBOCUP_SIMULATOR_ADDR"] == f"{sim_ip}:10002"
    assert env["ROBOCUP_TEAM_PLAYER2_IP"].rsplit(".", 1)[1] == "12"
    assert "ROBOCUP_TEAM_PLAYER3_IP" not in env
    assert (out / "teams/red/2/stdout.log").read_text().startswith("robot red-2 mode env")
    robot = results["robots"]["red-1"]
    assert robot["exit_code"] == 0 or robot["exit_code"] == 137
    assert robot["limits"]["nano_cpus"] == 1_000_000_000
    assert robot["limits"]["log_folder_bytes"] == 50_000_000
    assert robot["api"]["peer"] == env["ROBOCUP_TEAM_PLAYER1_IP"]
    assert set(results["timings_s"]) == {
        "pending", "pulling", "starting", "waiting", "playing", "stopping", "collecting"}
