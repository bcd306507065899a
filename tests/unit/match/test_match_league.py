"""League placement against in-memory fakes: node addresses in the robots' environment and the
spec, a holder per node in the node's network, the robot node firewall and shaping made before
the robot runs and undone at the end; parsing of the nodes a Slurm job passes; the
heterogeneous job the Slurm pool submits."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from orchestrator.errors import ConfigError
from orchestrator.match import MatchRunner, RunOptions
from orchestrator.match.fake import FakeContainer, FakeHost, FakeRuntime
from orchestrator.match.placement import ROBOT_CGROUP_PARENT, parse_nodes
from tests.unit.match.test_match_runner import _plan

KEYS = ["red-1", "red-2", "blue-1", "blue-2"]
NODES = "n1=10.77.0.11,n2=10.77.0.12,n3=10.77.0.13,n4=10.77.0.14,n5=10.77.0.15"


def test_league_match_runs_each_robot_in_its_nodes_network(tmp_path: Path) -> None:
    runtime = FakeRuntime()
    host = FakeHost()
    started: dict[str, FakeContainer] = {}
    firewalls_at_start: dict[str, int] = {}

    def on_start(container: FakeContainer) -> None:
        started[container.request.name] = container
        firewalls_at_start[container.request.name] = len(host.node_firewalls)

    runtime.on_start = on_start
    placement = parse_nodes(NODES, KEYS, netns="/run/netns/hlvs-{node}")
    runner = MatchRunner(_plan(), runtime=runtime, host=host, options=RunOptions(
        out_dir=tmp_path, simulator_image="sim:1", poll_s=0.0, placement=placement))
    outcome = runner.run()
    assert outcome.ok, outcome.failure
    assert runtime.networks == {} and not any(c == "create_network" for c, _ in runtime.calls)
    spec = json.loads((tmp_path / "simulator/match_spec.json").read_text())
    assert {c: spec[c]["hosts"] for c in ("red", "blue")} == {
        "red": ["10.77.0.12", "10.77.0.13"], "blue": ["10.77.0.14", "10.77.0.15"]}
    assert spec["network"]["telemetry_listen"] is None
    holders = {name: c for name, c in started.items() if "-node-" in name}
    assert sorted(holders) == [f"hlvs-u1-node-n{i}" for i in range(1, 6)]
    for i in range(1, 6):
        request = holders[f"hlvs-u1-node-n{i}"].request
        assert request.network_mode == "none" and request.cap_add == ("SYS_ADMIN",)
        assert request.cap_drop == ("ALL",)
        assert [str(m.source) for m in request.mounts] == [f"/run/netns/hlvs-n{i}"]
        assert request.entrypoint == ("nsenter",)
    ids = {name: c.state.id for name, c in started.items()}
    simulator = started["hlvs-u1-simulator"].request
    assert simulator.network_mode == f"container:{ids['hlvs-u1-node-n1']}"
    assert simulator.networks == ()
    red2 = started["hlvs-u1-red-2"].request
    assert red2.network_mode == f"container:{ids['hlvs-u1-node-n3']}"
    assert red2.cgroup_parent == ROBOT_CGROUP_PARENT
    assert red2.labels["org.hlvs-runner.node"] == "n3"  # the node's epilog finds it
    assert simulator.labels["org.hlvs-runner.node"] == "n1"
    assert red2.environment["ROBOCUP_SIMULATOR_ADDR"] == "10.77.0.11:10002"
    assert red2.environment["ROBOCUP_MIRROR_SERVER_IP"] == "10.77.0.11"
    assert red2.environment["ROBOCUP_GAMECONTROLLER_IP"] == "10.77.0.11"
    assert red2.environment["ROBOCUP_TEAM_PLAYER1_IP"] == "10.77.0.12"
    assert red2.environment["ROBOCUP_TEAM_PLAYER2_IP"] == "10.77.0.13"
    blue1 = started["hlvs-u1-blue-1"].request
    assert blue1.environment["ROBOCUP_TEAM_PLAYER2_IP"] == "10.77.0.15"
    assert firewalls_at_start["hlvs-u1-blue-1"] >= 1  # its node was closed before it ran
    # every firewall and shaping undone; what they were:
    assert host.node_firewalls == {}
    assert sorted(host.unshaped) == [f"/run/netns/hlvs-n{i}" for i in range(2, 6)]
    red_mates = {s.teammate_ips for s in host.shaped if s.teammate_ips == ("10.77.0.13",)}
    assert red_mates and all(s.simulator_ip == "10.77.0.11" for s in host.shaped)
    results = json.loads((tmp_path / "results.json").read_text())
    assert results["robots"]["red-1"]["limits"]["api_rate_bit_s"] == 40_000_000


def test_league_firewall_rules_name_the_nodes(tmp_path: Path) -> None:
    host = FakeHost()
    seen: dict[str, object] = {}
    runtime = FakeRuntime()
    runtime.on_start = lambda c: seen.update(host.node_firewalls)
    placement = parse_nodes(NODES, KEYS, netns="/run/netns/hlvs-{node}")
    MatchRunner(_plan(), runtime=runtime, host=host, options=RunOptions(
        out_dir=tmp_path, simulator_image="sim:1", poll_s=0.0, placement=placement)).run()
    red1 = seen["/run/netns/hlvs-n2"]
    assert red1 == type(red1)(simulator="10.77.0.11", api_port=10001, udp_ports=(3737, 3939),
                              teammates=("10.77.0.13",),
                              opponents=("10.77.0.14", "10.77.0.15"))
    assert "/run/netns/hlvs-n1" not in seen  # the simulator's node has no robot firewall


@pytest.mark.parametrize(("text", "netns", "expected"), [
    ("n1=10.77.0.11,n2=10.77.0.12", None, "nodes for 4 robots"),
    (NODES.replace("n5=10.77.0.15", "n4=10.77.0.15"), None, "named twice"),
    (NODES.replace("10.77.0.13", "ten"), None, "is not NAME=ADDRESS"),
    (NODES, "/run/netns/fixed", "does not name the node"),
])
def test_bad_league_nodes_are_named(text: str, netns: str | None, expected: str) -> None:
    with pytest.raises(ConfigError) as err:
        parse_nodes(text, KEYS, netns=netns)
    assert expected in str(err.value)


def test_slurm_pool_submits_a_heterogeneous_job_for_league_placement(tmp_path: Path) -> None:
    from cluster import MatchJob
    from cluster.slurm import SlurmPool

    calls: list[tuple[list[str], str | None]] = []

    class Recording(SlurmPool):  # Slurm's commands recorded at the adapter's one boundary
        def _run(self, args: list[str], *, handle: str, stdin: str | None = None,
                 ok_codes: tuple[int, ...] = (0,)) -> str:
            calls.append((args, stdin))
            if args[0] == "squeue":
                return ("7+0|hlvs-m|a|RUNNING|None|2026-01-01T00:00:00|n1\n"
                        "7+1|hlvs-m|a|RUNNING|None|2026-01-01T00:00:00|n2\n"
                        "7+2|hlvs-m|a|RUNNING|None|2026-01-01T00:00:00|n3\n")
            return "7\n" if args[0] == "sbatch" else ""

    pool = Recording(out_subdir="", host_network=True)
    handle = pool.submit(MatchJob(match_id="m", game_path=tmp_path / "g.json",
                                  work_dir=tmp_path / "w", account="team_a", robot_nodes=2))
    args, script = calls[0]
    assert args.count(":") == 2 and args.count("--exclusive") == 3
    assert args.count("--account=team_a") == 3
    assert args.count("--constraint=sim") == 1 and args.count("--constraint=robot") == 2
    assert script is not None and "SLURM_JOB_NODELIST_HET_GROUP_$group" in script
    assert "--placement league --league-nodes \"$nodes\"" in script
    assert "--node-netns '/run/netns/hlvs-{node}'" in script
    status = pool.status(handle)
    assert status.detail == "on n1,n2,n3"
    assert [e.job_id for e in pool.queue()] == ["7"]


def test_schedule_pool_section_takes_a_placement(tmp_path: Path) -> None:
    from orchestrator.config.schedule import load_schedule
    from tournament.services import _robot_nodes

    for name in ("a", "b"):
        (tmp_path / f"{name}.json").write_text(json.dumps({"name": name, "players": {}}))

    def schedule(pool: str) -> Path:
        path = tmp_path / "s.yaml"
        path.write_text("name: cup\nteams:\n  - {name: a, id: 1, config: a.json}\n"
                        f"  - {{name: b, id: 2, config: b.json}}\npool: {pool}\n")
        return path

    pool = load_schedule(schedule("{kind: slurm, placement: league}")).pool
    assert (pool.kind, pool.placement) == ("slurm", "league")
    assert load_schedule(schedule("{kind: slurm}")).pool.placement == "dense"
    assert _robot_nodes(load_schedule(schedule("{kind: slurm}")).pool, tmp_path / "g.json") == 0
    with pytest.raises(ConfigError) as err:
        load_schedule(schedule("{kind: slurm, placement: spread}"))
    assert "/pool/placement" in str(err.value)


def test_league_schedule_asks_a_node_per_robot(tmp_path: Path) -> None:
    import argparse

    from orchestrator import add_scrimmage_arguments as add_arguments
    from orchestrator.config.schedule import SchedulePool
    from orchestrator.match import scrimmage
    from tournament.services import _robot_nodes

    parser = argparse.ArgumentParser()
    add_arguments(parser)
    args = parser.parse_args(["--players", "2", "--out", str(tmp_path / "m")])
    game = scrimmage.write_files(scrimmage.ScrimmageRequest.from_options(args), tmp_path / "config")
    assert _robot_nodes(SchedulePool(kind="slurm", placement="league"), game) == 4
    assert _robot_nodes(SchedulePool(kind="slurm"), game) == 0


def test_service_placement_setting(tmp_path: Path) -> None:
    from service.errors import SettingsError
    from service.settings import Settings

    base = {"HLVS_SERVICE_DATA_DIR": str(tmp_path)}
    found = Settings.from_env({**base, "HLVS_SERVICE_POOL": "slurm",
                               "HLVS_SERVICE_PLACEMENT": "league"})
    assert (found.pool, found.placement) == ("slurm", "league")
    assert Settings.from_env(base).placement == "dense"
    for env, expected in (({"HLVS_SERVICE_PLACEMENT": "league"}, "POOL=slurm"),
                          ({"HLVS_SERVICE_POOL": "slurm", "HLVS_SERVICE_PLACEMENT": "spread"},
                           "dense or league")):
        with pytest.raises(SettingsError) as err:
            Settings.from_env({**base, **env})
        assert "HLVS_SERVICE_PLACEMENT" in str(err.value) and expected in str(err.value)


def test_service_worker_asks_a_node_per_robot_in_league_placement(tmp_path: Path) -> None:
    import argparse

    from orchestrator import add_scrimmage_arguments as add_arguments
    from orchestrator.match import scrimmage
    from service.settings import Settings
    from service.worker import QueueWorker

    parser = argparse.ArgumentParser()
    add_arguments(parser)
    game = scrimmage.write_files(scrimmage.ScrimmageRequest.from_options(
        parser.parse_args(["--players", "3", "--out", str(tmp_path)])),
                                 tmp_path / "config")
    for env, nodes in (({"HLVS_SERVICE_POOL": "slurm", "HLVS_SERVICE_PLACEMENT": "league"}, 6),
                       ({"HLVS_SERVICE_POOL": "slurm"}, 0)):
        settings = Settings.from_env({"HLVS_SERVICE_DATA_DIR": str(tmp_path), **env})
        worker = QueueWorker(settings=settings, pool=None, sessions=None, sealer=None,  # type: ignore[arg-type]
                             changed=lambda _: None)
        assert worker._robot_nodes(game) == nodes


def test_containers_join_a_node_holder_only_once_it_is_in_the_nodes_network(
    tmp_path: Path,
) -> None:
    checks: list[str] = []

    class SlowHolders(FakeHost):  # nsenter has not entered the node's namespace at once
        def in_netns(self, pid: int, netns: str) -> bool:
            checks.append(netns)
            return checks.count(netns) > 2

    runtime = FakeRuntime()
    created_after: dict[str, int] = {}
    runtime.on_start = lambda c: created_after.setdefault(c.request.name, len(checks))
    placement = parse_nodes(NODES, KEYS, netns="/run/netns/hlvs-{node}")
    outcome = MatchRunner(_plan(), runtime=runtime, host=SlowHolders(), options=RunOptions(
        out_dir=tmp_path, simulator_image="sim:1", poll_s=0.0, placement=placement)).run()
    assert outcome.ok, outcome.failure
    assert sorted(set(checks)) == [f"/run/netns/hlvs-n{i}" for i in range(1, 6)]
    assert created_after["hlvs-u1-simulator"] >= 3  # after its holder's third check

    class NeverThere(FakeHost):
        def in_netns(self, pid: int, netns: str) -> bool:
            return False

    ticks = iter(range(0, 10_000, 5))
    outcome = MatchRunner(_plan(), runtime=FakeRuntime(), host=NeverThere(), options=RunOptions(
        out_dir=tmp_path / "never", simulator_image="sim:1", poll_s=0.0, placement=placement),
        clock=lambda: float(next(ticks))).run()
    assert not outcome.ok
    assert "did not enter /run/netns/hlvs-n" in str(outcome.failure)
