"""``hlvs compose`` output run by Debian's docker-compose 1.29: networks, addresses, environment
and confinement as the match has them, checked by stand-in containers."""

from __future__ import annotations

import ipaddress
import json
import random
import shutil
import subprocess
import uuid
from pathlib import Path
from typing import Any

import docker
import pytest
import yaml

from orchestrator.compose import Subnets, collect_results, compose_files, write_compose
from orchestrator.config import load_game
from orchestrator.project_images import project_image
from tests.conftest import TEST_LABEL

pytestmark = pytest.mark.docker

EXAMPLE = Path(__file__).parents[3] / "configs" / "examples" / "scrimmage_1v1" / "game.json"

# The simulator stand-in accepts one robot per API port, greets it as the simulator does, records
# the peer address and the robot's report, and exits once both robots reported (which ends the
# compose run).
SIMULATOR = r"""
import json, socket, select, time
servers = {}
for port in (10001, 10021):
    s = socket.socket(); s.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
    s.bind(("0.0.0.0", port)); s.listen(1); servers[s] = port
peers, reports, deadline = {}, {}, time.time() + 90
while len(peers) < 2 and time.time() < deadline:
    ready, _, _ = select.select(list(servers), [], [], 1.0)
    for s in ready:
        conn, addr = s.accept(); conn.sendall(b"Welcome\0"); peers[servers[s]] = addr[0]
        conn.settimeout(10); data = b""
        while chunk := conn.recv(65536):
            data += chunk
        reports[servers[s]] = json.loads(data)
json.dump({"peers": peers, "reports": reports}, open("/match/out/stand_in.json", "w"))
"""

# A robot stand-in tries the other team's simulator address, writes its environment and privileges
# to /robocup-logs, sends the same report to ROBOCUP_SIMULATOR_ADDR, then waits to be stopped.
ROBOT = r"""
import json, os, socket, time
cross = "connected"
try:
    socket.create_connection((os.environ["OTHER_SIMULATOR"], 10001), timeout=2).close()
except OSError as exc:
    cross = type(exc).__name__
lines = open("/proc/self/status").read().splitlines()
status = dict(line.split(":\t", 1) for line in lines if ":\t" in line)
report = {
    "env": {k: v for k, v in os.environ.items() if k.startswith("ROBOCUP_")},
    "cross_team": cross,
    "cap_eff": status["CapEff"].strip(),
    "no_new_privs": status["NoNewPrivs"].strip(),
}
json.dump(report, open("/robocup-logs/probe.json", "w"))
host, port = os.environ["ROBOCUP_SIMULATOR_ADDR"].split(":")
for _ in range(120):
    try:
        with socket.create_connection((host, int(port)), timeout=2) as s:
            report["greeting"] = s.recv(8).decode(errors="replace")
            s.sendall(json.dumps(report).encode())
        break
    except OSError:
        time.sleep(0.5)
time.sleep(300)
"""


def test_compose_document_follows_the_match_layout() -> None:
    loaded = load_game(EXAMPLE, images_required=True)
    subnets = Subnets.starting_at(ipaddress.IPv4Network("10.99.0.0/24"))
    document, spec = compose_files(loaded, simulator_image="sim:x", subnets=subnets, cpu_count=1)

    assert "version" not in document  # obsolete in the Compose specification
    assert set(document["services"]) == {"simulator", "red-1", "blue-1"}
    assert all(net["internal"] for net in document["networks"].values())
    simulator = document["services"]["simulator"]
    assert simulator["networks"] == {
        "red": {"ipv4_address": "10.99.0.2"},
        "blue": {"ipv4_address": "10.99.1.2"},
        "control": {"ipv4_address": "10.99.2.2"},
    }
    red = document["services"]["red-1"]
    assert red["networks"] == {"red": {"ipv4_address": "10.99.0.11"}}
    assert red["environment"]["ROBOCUP_SIMULATOR_ADDR"] == "10.99.0.2:10001"
    assert red["environment"]["ROBOCUP_TEAM_PLAYER1_IP"] == "10.99.0.11"
    assert red["cap_drop"] == ["ALL"] and red["security_opt"] == ["no-new-privileges"]
    assert (red["cpus"], red["mem_limit"], red["pids_limit"]) == (1.0, 1_000_000_000, 256)
    assert red["command"] == ["striker", "--start-pose", "-1.0", "-3.1", "1.57"]
    assert spec["red"]["robot_addresses"] == ["10.99.0.11"]
    assert spec["network"]["telemetry_listen"] == "tcp/10.99.2.2:7447"


def test_compose_up_gives_robots_their_network_and_environment(
    tmp_path: Path, docker_client: docker.DockerClient
) -> None:
    if shutil.which("docker-compose") is None:
        pytest.skip("docker-compose is not installed")
    loaded = load_game(EXAMPLE, images_required=True)
    third = random.Random().randrange(0, 80) * 3
    subnets = Subnets.starting_at(ipaddress.IPv4Network(f"10.215.{third}.0/24"))
    compose_path = tmp_path / "docker-compose.yml"
    image = project_image("team-base")
    write_compose(loaded, compose_path, simulator_image=image, subnets=subnets)
    _stand_ins(compose_path, image, subnets)
    project = f"hlvs-test-{uuid.uuid4().hex[:8]}"
    command = ["docker-compose", "-p", project, "-f", str(compose_path)]
    try:
        subprocess.run([*command, "config", "-q"], check=True, cwd=tmp_path)
        up = subprocess.run(
            [*command, "up", "--abort-on-container-exit", "--exit-code-from", "simulator"],
            cwd=tmp_path, capture_output=True, text=True, timeout=240,
        )  # fmt: skip
    finally:
        subprocess.run([*command, "down", "-v", "-t", "1"], cwd=tmp_path, capture_output=True)
    assert up.returncode == 0, up.stdout[-2000:] + up.stderr[-2000:]

    stand_in = json.loads((tmp_path / "out" / "stand_in.json").read_text())
    assert stand_in["peers"] == {"10001": f"10.215.{third}.11", "10021": f"10.215.{third + 1}.11"}
    for color, offset, port, team_id in (("red", 0, 10001, 1), ("blue", 1, 10021, 2)):
        report = stand_in["reports"][str(port)]
        written = json.loads((tmp_path / "logs" / f"{color}-1" / "probe.json").read_text())
        assert written == {k: v for k, v in report.items() if k != "greeting"}
        sim = f"10.215.{third + offset}.2"
        assert report["greeting"] == "Welcome\0"
        assert report["env"] == {
            "ROBOCUP_ROBOT_ID": "1",
            "ROBOCUP_TEAM_COLOR": color,
            "ROBOCUP_TEAM_ID": str(team_id),  # the team's number in game.json
            "ROBOCUP_SIMULATOR_ADDR": f"{sim}:{port}",
            "ROBOCUP_MIRROR_SERVER_IP": sim,
            "ROBOCUP_GAMECONTROLLER_IP": sim,
            "ROBOCUP_TEAM_PLAYER1_IP": f"10.215.{third + offset}.11",
        }
        assert report["cross_team"] != "connected"
        assert int(report["cap_eff"], 16) == 0
        assert report["no_new_privs"] == "1"
    compose_label = f"com.docker.compose.project={project}"
    assert docker_client.containers.list(all=True, filters={"label": compose_label}) == []
    assert docker_client.networks.list(filters={"label": compose_label}) == []


def _stand_ins(compose_path: Path, image: str, subnets: Subnets) -> None:
    """Swap the simulator and the robots for the stand-ins above (same layout otherwise)."""
    text = compose_path.read_text()
    document: dict[str, Any] = yaml.safe_load(text)
    project_label = {TEST_LABEL: "1"}
    sim = document["services"]["simulator"]
    sim["command"] = ["python3", "-c", SIMULATOR]
    sim["labels"].update(project_label)
    for color, other in (("red", "blue"), ("blue", "red")):
        robot = document["services"][f"{color}-1"]
        robot["image"] = image
        robot["command"] = ["python3", "-c", ROBOT]
        robot["environment"]["OTHER_SIMULATOR"] = str(subnets.of(other).network_address + 2)
        robot["labels"].update(project_label)
        robot["stop_grace_period"] = "1s"
    for network in document["networks"].values():
        network["labels"].update(project_label)
    compose_path.write_text(yaml.safe_dump(document, sort_keys=False))


def _game_copy(tmp_path: Path, *, robot_image: str, robot_cmd: str | None) -> Path:
    """The 1 v 1 example with short halves and the given robot image and command."""
    source = EXAMPLE.parent
    game = json.loads((source / "game.json").read_text())
    game["match_id"] = f"compose-{uuid.uuid4().hex[:6]}"
    game["timing"].update({"half_duration_s": 4, "ready_duration_s": 1, "grace_period_s": 1,
                           "minimum_play_s": 0})
    (tmp_path / "game.json").write_text(json.dumps(game))
    for name in ("team_red.json", "team_blue.json"):
        team = json.loads((source / name).read_text())
        repository, _, tag = robot_image.rpartition(":")
        team["image"] = repository
        for player in team["players"].values():
            player["dockerTag"] = tag
            if robot_cmd is not None:
                player["dockerCmd"] = robot_cmd
        (tmp_path / name).write_text(json.dumps(team))
    return tmp_path / "game.json"


def _compose_up(folder: Path, compose_path: Path) -> subprocess.CompletedProcess[str]:
    project = f"hlvs-test-{uuid.uuid4().hex[:8]}"
    command = ["docker-compose", "-p", project, "-f", str(compose_path)]
    try:
        return subprocess.run(
            [*command, "up", "--abort-on-container-exit", "--exit-code-from", "simulator"],
            cwd=folder, capture_output=True, text=True, timeout=300,
        )  # fmt: skip
    finally:
        subprocess.run([*command, "down", "-v", "-t", "1"], cwd=folder, capture_output=True)


@pytest.mark.slow
def test_compose_up_plays_a_stub_match(tmp_path: Path) -> None:
    """The simulator and stub images play a short 1 v 1 match to the end under docker-compose."""
    if shutil.which("docker-compose") is None:
        pytest.skip("docker-compose is not installed")
    game = _game_copy(tmp_path, robot_image=project_image("stub"), robot_cmd=None)
    loaded = load_game(game, images_required=True)
    third = random.Random().randrange(0, 80) * 3
    subnets = Subnets.starting_at(ipaddress.IPv4Network(f"10.216.{third}.0/24"))
    compose_path = tmp_path / "run" / "docker-compose.yml"
    write_compose(
        loaded, compose_path, simulator_image=project_image("simulator"), subnets=subnets
    )

    up = _compose_up(compose_path.parent, compose_path)

    assert up.returncode == 0, up.stdout[-3000:] + up.stderr[-2000:]
    result = json.loads((compose_path.parent / "out" / "sim_result.json").read_text())
    assert result["match_id"] == loaded.game.match_id
    assert result["state"] == "FINISHED"
    assert result["seed"] == loaded.game.seed
    for robot in ("red-1", "blue-1"):
        stats = result["robots"][robot]
        assert len(stats["connects"]) >= 1, stats  # the stub reached its API port
        assert stats["messages_in"] > 0 and stats["messages_out"] > 0
        robot_logs = list((compose_path.parent / "logs" / robot).iterdir())
        assert robot_logs and all(p.stat().st_size > 0 for p in robot_logs)
    for name in ("replay.hlvsrec", "referee.log", "gamecontroller.log"):
        assert (compose_path.parent / "out" / name).stat().st_size > 0
    results = collect_results(loaded, compose_path.parent)  # hlvs compose --collect
    assert results.ok and results.final_state == "FINISHED", results.failure
    report = json.loads((compose_path.parent / "report.json").read_text())
    assert report == {"status": "success"}
    written = json.loads((compose_path.parent / "results.json").read_text())
    assert written["match_id"] == loaded.game.match_id and written["play"] is not None
