"""Limits of robot containers: bandwidth, CPU/memory/pids as the engine sees them, OOM, log cap,
grace period."""

from __future__ import annotations

import json

import docker
import pytest

from orchestrator.config import Limits
from orchestrator.engine import LABEL_ROLE
from orchestrator.runtime.port import ContainerRequest, NetworkRequest
from tests.integration.match.conftest import MatchFactory

pytestmark = [pytest.mark.docker, pytest.mark.root]


def test_robot_to_simulator_throughput_is_held_to_the_configured_rate(
    play: MatchFactory,
) -> None:
    limits = Limits(cpus=1.0, memory_gb=0.5, log_folder_gb=0.05, team_api_mb_s=5.0)  # 40 Mbit/s
    outcome = play(red=[["send", "4"]], blue=[["listen"]], sim=("7",), limits=limits)
    results = json.loads((outcome.out_dir / "results.json").read_text())
    red = results["robots"]["red-1"]
    assert red["limits"]["api_rate_bit_s"] == 40_000_000
    rate = red["api"]["rate_bit_s"]
    windows = red["api"]["window_rates_bit_s"]
    assert rate is not None and len(windows) >= 2, red
    # never more than the limit, over the whole send and in any second of it ...
    assert rate <= 1.02 * 40e6, rate
    assert max(windows) <= 1.05 * 40e6, windows
    # ... and the sender did fill the link (a second of it at the limit; on a loaded machine
    # the sender or the receiver may be starved in others)
    assert max(windows) >= 0.9 * 40e6, windows
    assert red["sent_bytes"] >= red["api"]["bytes"]


def test_limits_are_visible_in_docker_inspect(
    play: MatchFactory, docker_client: docker.DockerClient
) -> None:
    seen: dict[str, object] = {}

    def capture(request: ContainerRequest | NetworkRequest) -> None:
        if isinstance(request, ContainerRequest) and request.labels.get(LABEL_ROLE) == "robot":
            attrs = docker_client.api.inspect_container(request.name)
            seen[attrs["Name"]] = attrs["HostConfig"]

    limits = Limits(cpus=1.5, memory_gb=0.25, pids=64, log_folder_gb=0.02)
    outcome = play(red=[["env"]], blue=[["env"]], sim=("2",), limits=limits,
                   on_created=capture)
    assert outcome.ok
    assert len(seen) == 2
    for host_config in seen.values():
        # 1.5 CPUs, enforced over 10 ms periods
        assert (host_config["CpuQuota"], host_config["CpuPeriod"]) == (15_000, 10_000)
        assert host_config["Memory"] == 250_000_000
        assert host_config["MemorySwap"] == 250_000_000
        assert host_config["PidsLimit"] == 64
        assert host_config["CapDrop"] == ["ALL"]
        assert host_config["SecurityOpt"] == ["no-new-privileges"]
        assert host_config["Privileged"] is False
        # on its team's network (behind the start gate, which is bound read-only with the
        # folder it waited in)
        assert host_config["NetworkMode"] in (f"hlvs-{outcome.match_id}-red",
                                              f"hlvs-{outcome.match_id}-blue")
        binds = {b.rpartition(":")[0].rpartition(":")[2]: b.rpartition(":")[2]
                 for b in host_config["Binds"]}
        assert sorted(binds) == ["/.hlvs-start-gate", "/.hlvs-start-gate.d", "/robocup-logs",
                                 "/root", "/tmp", "/var/tmp"]
        assert binds["/.hlvs-start-gate"] == binds["/.hlvs-start-gate.d"] == "ro"
        assert host_config["ReadonlyRootfs"] is True


def test_robots_behind_holders_where_the_gate_cannot_be_built(
    play: MatchFactory, docker_client: docker.DockerClient
) -> None:
    """Without the start gate each robot joins the network of its holder, which is shaped
    first: the match plays, shaped, as behind the gate."""
    seen: dict[str, object] = {}

    def capture(request: ContainerRequest | NetworkRequest) -> None:
        if isinstance(request, ContainerRequest) and request.labels.get(LABEL_ROLE) == "robot":
            seen[request.name] = docker_client.api.inspect_container(request.name)["HostConfig"]

    outcome = play(red=[["env"]], blue=[["env"]], sim=("2",), on_created=capture, holders=True)
    assert outcome.ok
    results = json.loads((outcome.out_dir / "results.json").read_text())
    assert len(seen) == 2
    for host_config in seen.values():
        assert host_config["NetworkMode"].startswith("container:")
        assert not any("start-gate" in b for b in host_config["Binds"])
    for robot in results["robots"].values():
        assert robot["limits"]["api_rate_bit_s"] > 0 and robot["sent_bytes"] > 0, robot


def test_oom_killed_robot_is_recorded_and_the_game_goes_on(play: MatchFactory) -> None:
    limits = Limits(cpus=1.0, memory_gb=0.06, log_folder_gb=0.02)
    outcome = play(red=[["oom"]], blue=[["env"]], sim=("5",), limits=limits)
    results = json.loads((outcome.out_dir / "results.json").read_text())
    assert outcome.ok, results["failure"]
    red = results["robots"]["red-1"]
    assert red["oom_killed"] is True
    assert red["exit_code"] == 137
    assert red["exited_during_game"] is True
    assert results["final_state"] == "FINISHED"


def test_robot_writing_past_its_log_cap_fills_only_its_folder(play: MatchFactory) -> None:
    outcome = play(red=[["fill"]], blue=[["env"]], sim=("5",),
                   limits=Limits(cpus=1.0, memory_gb=0.5, log_folder_gb=0.02))
    assert outcome.ok
    line = (outcome.out_dir / "teams/red/1/stdout.log").read_text().splitlines()[-1]
    report = json.loads(line)
    assert "No space left on device" in report["error"]
    assert 10 * 2**20 <= report["written"] <= 20_000_000
    size = (outcome.out_dir / "teams/red/1/robocup-logs/big.bin").stat().st_size
    assert size <= 20_000_000


def test_sigterm_handling_robot_gets_its_grace_period(play: MatchFactory) -> None:
    outcome = play(red=[["sigterm"]], blue=[["env"]], sim=("4",), grace_s=4.0)
    assert outcome.ok
    text = (outcome.out_dir / "teams/red/1/robocup-logs/term.txt").read_text()
    assert text == "got SIGTERM\nflushed\n"
    results = json.loads((outcome.out_dir / "results.json").read_text())
    assert results["robots"]["red-1"]["exit_code"] == 0
    assert results["robots"]["blue-1"]["exit_code"] == 137  # ignores SIGTERM: killed after grace
    assert results["timings_s"]["stopping"] >= 3.5


def test_simulator_to_robot_and_teammate_traffic_are_held_to_their_rates(
    play: MatchFactory,
) -> None:
    # red: 2 robots, API 2.5 MB/s each, team comm 0.5 MB/s each (4 Mbit/s); blue: 1 robot, 5 MB/s
    limits = Limits(cpus=1.0, memory_gb=0.5, log_folder_gb=0.02, team_api_mb_s=5.0,
                    team_comm_mb_s=1.0)
    outcome = play(red=[["sink"], ["sendmate", "4"]], blue=[["recv", "4"]], sim=("8",),
                   limits=limits)
    out = outcome.out_dir
    download = json.loads((out / "teams/blue/1/robocup-logs/recv.json").read_text())["rate_bit_s"]
    assert 0.9 * 40e6 <= download <= 1.02 * 40e6, download
    mates = json.loads((out / "teams/red/1/robocup-logs/sink.json").read_text())["rate_bit_s"]
    assert 0.9 * 4e6 <= mates <= 1.02 * 4e6, mates
    results = json.loads((out / "results.json").read_text())
    assert results["robots"]["blue-1"]["received_bytes"] >= 4 * 0.9 * 40e6 / 8 * 0.8
