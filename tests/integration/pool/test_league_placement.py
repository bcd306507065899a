"""League placement on the five-node cluster: a 2 v 2 scrimmage as one heterogeneous Slurm job,
the simulator on one node and each robot on a node of its own, with its node's network.

The robots connect, play and are isolated: from inside a robot container (its processes, in its
node's network), the simulator's port and the teammate's node answer; the opponents' nodes, the
controller and the simulator's telemetry port do not. A cancelled league match stops its robots
with their grace period. Either way nothing of the match is left on any node: no container, no
firewall chain, no traffic shaping; nor when the match's orchestrator is killed (the cluster's
epilog on each node cleans up).
"""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path
from typing import Any

import docker
import pytest

pytestmark = [pytest.mark.docker, pytest.mark.root, pytest.mark.slow]

CONTROLLER = ("10.77.0.1", 6817)  # slurmctld: the control network
SLURMD_PORT = 6818  # listens on every node's address

PROBE = """
import json, socket, sys
found = {}
for name, host, port in json.loads(sys.argv[1]):
    try:
        socket.create_connection((host, port), timeout=3).close()
        found[name] = "connected"
    except OSError as exc:
        found[name] = f"failed: {exc}"
udp = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
udp.connect(("10.77.0.1", 9))
found["own address"] = udp.getsockname()[0]
print(json.dumps(found))
"""

LISTEN = """
import json, select, socket, sys, time
socks = {}
for port in (3737, 5999):
    s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    s.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 4 << 20)
    s.bind(("0.0.0.0", port))
    socks[s] = port
got = {"mirror": [], "blast_bytes": 0, "blast_first": None, "blast_last": None}
end = time.monotonic() + float(sys.argv[1])
while time.monotonic() < end:
    ready, _, _ = select.select(list(socks), [], [], 0.2)
    for s in ready:
        data, peer = s.recvfrom(65535)
        if socks[s] == 3737:
            got["mirror"].append([data.decode(errors="replace"), peer[0]])
        else:
            now = time.monotonic()
            got["blast_first"] = got["blast_first"] or now
            got["blast_last"] = now
            got["blast_bytes"] += len(data)
print(json.dumps(got))
"""

SEND = """
import socket, sys, time
simulator, mate = sys.argv[1], sys.argv[2]
s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
for i in range(5):
    s.sendto(f"team message {i}".encode(), (simulator, 3737))
    time.sleep(0.2)
payload = bytes(1200)
end = time.monotonic() + 3.0
while time.monotonic() < end:
    try:
        s.sendto(payload, (mate, 5999))
    except OSError:
        time.sleep(0.001)  # the shaper's queue is full
print("sent")
"""


def _team_traffic(sender: Any, receiver: Any, simulator: str, mate: str) -> dict[str, Any]:
    """Team messages through the mirror, then 3 s of UDP as fast as the sender can, from
    ``sender`` to ``receiver``'s node: what ``receiver`` got (its node's limits apply)."""
    result: dict[str, Any] = {}

    def listen() -> None:
        code, output = receiver.exec_run(["python3", "-c", LISTEN, "8"])
        result.update(json.loads(output.decode().strip().splitlines()[-1]) if code == 0
                      else {"error": output.decode()})

    thread = threading.Thread(target=listen)
    thread.start()
    time.sleep(1.5)  # the listener binds
    code, output = sender.exec_run(["python3", "-c", SEND, simulator, mate])
    thread.join(timeout=30)
    assert code == 0, output
    return result


def _scrimmage(cluster: str, out: Path, match_id: str, half_s: int) -> subprocess.Popen[str]:
    cmd = [sys.executable, "-m", "hlvs", "scrimmage", "--pool", "slurm",
           "--placement", "league", "--players", "2", "--slurm-conf", cluster,
           "--half-duration", str(half_s), "--ready-duration", "1",
           "--minimum-play", "0", "--wait-before-ready", "1",
           "--grace", "5", "--match-id", match_id, "--out", str(out), "--json"]
    return subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)


def _robots(client: docker.DockerClient, match_id: str, proc: subprocess.Popen[str]
            ) -> dict[str, Any]:
    """The four robot containers once they all run (key -> container); the job waits for five
    free nodes at once, longer while other jobs hold some."""
    deadline = time.monotonic() + 600
    while time.monotonic() < deadline:
        found = client.containers.list(filters={"label": [f"org.hlvs-runner.match={match_id}",
                                                          "org.hlvs-runner.role=robot"]})
        if len(found) == 4:
            return {f"{c.labels['org.hlvs-runner.team']}-{c.labels['org.hlvs-runner.robot']}": c
                    for c in found}
        assert proc.poll() is None, proc.communicate()
        time.sleep(0.5)
    raise AssertionError("the four robots did not start")


def _connected(robots: dict[str, Any]) -> None:
    """Until every robot's code runs (a container's first process ignores SIGTERM until the
    robot installs its handler)."""
    deadline = time.monotonic() + 120
    while not all(b"connected to the simulator" in c.logs() for c in robots.values()):
        assert time.monotonic() < deadline, "the robots did not connect"
        time.sleep(0.5)


def _env(container: Any) -> dict[str, str]:
    return dict(item.split("=", 1) for item in container.attrs["Config"]["Env"])


def _probe(container: Any, targets: list[tuple[str, str, int]]) -> dict[str, str]:
    code, output = container.exec_run(["python3", "-c", PROBE, json.dumps(targets)])
    assert code == 0, output
    return dict(json.loads(output.decode().strip().splitlines()[-1]))


def _sacct(cluster: str, job_id: str) -> list[tuple[str, str, str]]:
    text = subprocess.run(["sacct", "-n", "-P", "-j", job_id, "-o", "JobID,State,NodeList"],
                          capture_output=True, text=True, check=True,
                          env={**os.environ, "SLURM_CONF": cluster}).stdout
    return [(a, b, c) for a, b, c in (line.split("|") for line in text.splitlines())
            if "." not in a]  # the job's components, not its steps


def _node_address(cluster: str, node: str) -> str:
    text = subprocess.run(["scontrol", "show", "node", node, "-o"], capture_output=True,
                          text=True, check=True, env={**os.environ, "SLURM_CONF": cluster}).stdout
    return next(f.split("=", 1)[1] for f in text.split() if f.startswith("NodeAddr="))


def _nothing_left(client: docker.DockerClient, match_id: str) -> None:
    assert client.containers.list(all=True, filters={
        "label": f"org.hlvs-runner.match={match_id}"}) == []
    for n in range(1, 6):
        inside = ["nsenter", f"--net=/run/netns/hlvs-n{n}"]
        rules = subprocess.run([*inside, "iptables", "-w", "-S"], capture_output=True,
                               text=True, check=True).stdout
        assert "HLVS-ROBOTS" not in rules, (n, rules)
        qdisc = subprocess.run([*inside, "tc", "qdisc", "show", "dev", "eth0"],
                               capture_output=True, text=True, check=True).stdout
        host_side = subprocess.run(["tc", "qdisc", "show", "dev", f"hlvsn{n}"],
                                   capture_output=True, text=True, check=True).stdout
        assert "htb" not in qdisc and "htb" not in host_side, (n, qdisc, host_side)


def test_league_2v2_on_four_robot_nodes_connects_plays_and_is_isolated(
    cluster: str, tmp_path: Path
) -> None:
    client = docker.from_env()
    out = tmp_path / "league"
    match_id = f"league-{os.getpid()}"
    proc = _scrimmage(cluster, out, match_id, half_s=10)
    try:
        robots = _robots(client, match_id, proc)
        # the robots start beside the simulator, which listens once its world is built: the
        # probes wait until every robot's own client got through (the simulator listens)
        _connected(robots)
        env = {key: _env(c) for key, c in robots.items()}
        simulator, api_port = env["red-1"]["ROBOCUP_SIMULATOR_ADDR"].split(":")
        node = {key: e[f"ROBOCUP_TEAM_PLAYER{key[-1]}_IP"] for key, e in env.items()}
        targets = {
            "red-1": [("simulator api", simulator, int(api_port)),
                      ("teammate node", node["red-2"], SLURMD_PORT),
                      ("blue-1 node", node["blue-1"], SLURMD_PORT),
                      ("blue-2 node", node["blue-2"], SLURMD_PORT),
                      ("controller", *CONTROLLER),
                      ("simulator telemetry", simulator, 7447)],
            "blue-1": [("red-1 node", node["red-1"], SLURMD_PORT),
                       ("red-2 node", node["red-2"], SLURMD_PORT),
                       ("teammate node", node["blue-2"], SLURMD_PORT),
                       ("controller", *CONTROLLER)],
        }
        reach = {key: _probe(robots[key], t) for key, t in targets.items()}
        team = _team_traffic(robots["red-1"], robots["red-2"], simulator, node["red-2"])
        stdout, stderr = proc.communicate(timeout=300)
    finally:
        if proc.poll() is None:
            proc.send_signal(signal.SIGINT)
            proc.communicate(timeout=300)
    assert proc.returncode == 0, stdout[-2000:] + stderr[-3000:]
    document = json.loads(stdout)
    assert document["final_state"] == "FINISHED"

    # four robot nodes, each robot's own, and the simulator's: the job's five components
    job_id = json.loads((out / "slurm.json").read_text())["job_id"]
    components = _sacct(cluster, job_id)
    assert [state for _, state, _ in components] == ["COMPLETED"] * 5, components
    nodes = [n for _, _, n in components]
    assert len(set(nodes)) == 5, components
    assert simulator == _node_address(cluster, nodes[0])
    assert sorted(node.values()) == sorted(_node_address(cluster, n) for n in nodes[1:])
    for key, e in env.items():  # the real node addresses in every robot's environment
        assert e["ROBOCUP_MIRROR_SERVER_IP"] == simulator
        assert e["ROBOCUP_SIMULATOR_ADDR"].startswith(f"{simulator}:")
        mate = ("red-" if key.startswith("red") else "blue-") + ("2" if key[-1] == "1" else "1")
        assert e[f"ROBOCUP_TEAM_PLAYER{mate[-1]}_IP"] == node[mate]

    # isolated: each robot has its node's address; only its simulator port and teammate answer
    for key in ("red-1", "blue-1"):
        assert reach[key]["own address"] == node[key], reach
        assert reach[key]["teammate node"] == "connected", reach
    assert reach["red-1"]["simulator api"] == "connected", reach
    for key, names in (("red-1", ("blue-1 node", "blue-2 node", "controller",
                                  "simulator telemetry")),
                       ("blue-1", ("red-1 node", "red-2 node", "controller"))):
        for name in names:
            assert reach[key][name].startswith("failed"), (key, name, reach[key][name])

    # the mirror relays a robot's team message to its teammate's node (from the simulator's)
    assert [text for text, _ in team["mirror"]][:1] == ["team message 0"], team
    assert {peer for _, peer in team["mirror"]} == {simulator}, team
    # the bandwidth limits hold per node: the teammate traffic leaving red 1's node is held
    # to its team communication rate (bytes per second, 10 % and one burst of slack)
    results = json.loads((out / "results.json").read_text())
    comm_bytes_s = results["robots"]["red-1"]["limits"]["comm_rate_bit_s"] / 8
    span = team["blast_last"] - team["blast_first"]
    assert span > 2.0, team
    assert team["blast_bytes"] <= comm_bytes_s * span * 1.1 + 64_000, (team, comm_bytes_s)
    assert team["blast_bytes"] >= comm_bytes_s * span * 0.5, (team, comm_bytes_s)

    # connected and played across the nodes: robot API, GameController, bandwidth limits
    for key in ("red-1", "red-2", "blue-1", "blue-2"):
        robot = results["robots"][key]
        assert robot["api"]["messages_in"] > 50, (key, robot["api"])
        assert robot["limits"]["api_rate_bit_s"] and robot["sent_bytes"] > 0, robot
        assert robot["spoofing_attempts"] == 0
    assert results["play"]["playing_s"] > 0, results["play"]
    gc_log = (out / "public" / "gamecontroller.log").read_text()
    returns = [int(line.split("returns received: ")[1].split(",")[0])
               for line in gc_log.splitlines() if "returns received: " in line]
    assert returns and returns[-1] > 0, gc_log[-500:]
    _nothing_left(client, match_id)


def test_cancelled_league_match_gives_robots_their_grace_period(
    cluster: str, tmp_path: Path
) -> None:
    client = docker.from_env()
    out = tmp_path / "cancel"
    match_id = f"league-cancel-{os.getpid()}"
    proc = _scrimmage(cluster, out, match_id, half_s=120)
    try:
        _connected(_robots(client, match_id, proc))  # cancelled once the robots' code runs
        job_id = json.loads((out / "slurm.json").read_text())["job_id"]
        subprocess.run(["scancel", job_id], check=True,
                       env={**os.environ, "SLURM_CONF": cluster})
        stdout, stderr = proc.communicate(timeout=300)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.communicate()
    assert proc.returncode == 130, stdout[-2000:] + stderr[-3000:]  # interrupted
    report = json.loads((out / "report.json").read_text())
    assert report["failure_class"] == "interrupted", report
    results = json.loads((out / "results.json").read_text())
    job_log = "\n".join(line for path in out.glob("slurm-*.out")
                         for line in path.read_text().splitlines()
                         if "WARNING" in line or "ERROR" in line or "stopping" in line)
    for key in ("red-1", "red-2", "blue-1", "blue-2"):  # SIGTERM, then they exit by themselves
        color, number = key.split("-")
        log = (out / "teams" / color / number / "stderr.log").read_text()
        assert results["robots"][key]["exit_code"] == 0, (key, log[-1500:], job_log[-3000:])
        assert "received SIGTERM" in log, log[-500:]
    states = {state.split()[0] for _, state, _ in _sacct(cluster, job_id)}
    assert states == {"CANCELLED"}, states
    _nothing_left(client, match_id)


def _orchestrator_pid(out: Path) -> int:
    """The job's ``hlvs match`` (the batch step on the simulator's node)."""
    deadline = time.monotonic() + 60
    while time.monotonic() < deadline:
        for proc_dir in Path("/proc").iterdir():
            try:
                args = (proc_dir / "cmdline").read_bytes().split(b"\0")
            except OSError:
                continue
            if b"--league-nodes" in args and str(out).encode() in args and b"match" in args:
                return int(proc_dir.name)
        time.sleep(0.5)
    raise AssertionError("no hlvs match with --league-nodes for " + str(out))


def test_killed_league_match_leaves_nothing_on_its_nodes(cluster: str, tmp_path: Path) -> None:
    """The orchestrator dies (kill -9) mid-match: the job ends, and the cluster's epilog on each
    of its nodes removes the containers placed there, the firewall chains and the shaping;
    ``hlvs cleanup --match`` then salvages the logs the match left."""
    client = docker.from_env()
    out = tmp_path / "killed"
    match_id = f"league-killed-{os.getpid()}"
    proc = _scrimmage(cluster, out, match_id, half_s=120)
    try:
        _connected(_robots(client, match_id, proc))
        job_id = json.loads((out / "slurm.json").read_text())["job_id"]
        rules = subprocess.run(["nsenter", "--net=/run/netns/hlvs-n2", "iptables", "-w", "-S"],
                               capture_output=True, text=True, check=True).stdout
        assert "-m cgroup --path hlvs-robots -j HLVS-ROBOTS" in rules, rules  # red 1's node
        os.kill(_orchestrator_pid(out), signal.SIGKILL)
        stdout, stderr = proc.communicate(timeout=300)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.communicate()
    assert proc.returncode == 3, stdout[-2000:] + stderr[-3000:]  # infrastructure
    assert f"Slurm job {job_id} ended" in stderr, stderr[-2000:]
    states = {state.split()[0] for _, state, _ in _sacct(cluster, job_id)}
    assert "RUNNING" not in states and "COMPLETED" not in states, states
    deadline = time.monotonic() + 60
    while True:  # the epilogs run as the job's nodes are released
        try:
            _nothing_left(client, match_id)
            break
        except AssertionError:
            if time.monotonic() > deadline:
                raise
            time.sleep(1)
    salvage = subprocess.run([sys.executable, "-m", "hlvs", "cleanup", "--match",
                              match_id], capture_output=True, text=True, timeout=300,
                             check=False)
    assert salvage.returncode == 0, salvage.stdout + salvage.stderr
    assert json.loads((out / "report.json").read_text())["failure_class"] == "interrupted"
    assert (out / "teams" / "red" / "1").is_dir()
