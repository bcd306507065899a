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
    seen = json.loads((out / "teams/red/2/robocup-logs/env.json").read_text())
    env = seen["env"]
    assert set(env) == {
        "ROBOCUP_ROBOT_ID", "ROBOCUP_TEAM_COLOR", "ROBOCUP_SIMULATOR_ADDR",
        "ROBOCUP_MIRROR_SERVER_IP", "ROBOCUP_GAMECONTROLLER_IP", "ROBOCUP_TEAM_PLAYER1_IP",
        "ROBOCUP_TEAM_PLAYER2_IP",
    }
    assert seen["hostname"] == "red-2"
    assert seen["cap_eff"] == "0000000000000000" and seen["no_new_privs"] == "1"
    host_mounts = [m for m in seen["mounts"] if not m.startswith(("/proc", "/sys", "/dev"))]
    assert sorted(host_mounts) == [
        "/", "/.hlvs-start-gate", "/.hlvs-start-gate.d", "/etc/hostname", "/etc/hosts",
        "/etc/resolv.conf", "/robocup-logs", "/root", "/run", "/tmp", "/var/tmp",
    ]  # a read-only root and start gate; writable: the capped scratch folders
    blue = json.loads((out / "teams/blue/1/robocup-logs/env.json").read_text())["env"]
    assert blue["ROBOCUP_TEAM_COLOR"] == "blue"
    assert blue["ROBOCUP_SIMULATOR_ADDR"].endswith(":10021")
    assert "ROBOCUP_TEAM_PLAYER2_IP" not in blue
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
