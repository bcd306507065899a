"""Robots started behind the start gate (against in-memory fakes): one container a robot, on
its team's network, shaped before the gate lets its program run."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from orchestrator.bandwidth import AppliedShaping, RobotShaping, TrafficCounters
from orchestrator.config import Limits
from orchestrator.errors import InfrastructureError
from orchestrator.match import MatchOutcome, MatchPlan, MatchRunner, RobotPlan, RunOptions, TeamPlan
from orchestrator.match import gate as gate_mod
from orchestrator.match.fake import FakeHost, FakeRuntime
from orchestrator.runtime.port import ContainerRequest
from testkit.specs import match_spec

GATE = Path("/opt/gate/start_gate")


def _plan(commands: dict[str, tuple[str, ...] | None] | None = None) -> MatchPlan:
    commands = commands or {}

    def robots(color: str) -> tuple[RobotPlan, ...]:
        base = 10000 if color == "red" else 10020
        return tuple(RobotPlan(color=color, number=i, port=base + i, image=f"team/{color}:1",
                               command=commands.get(f"{color}-{i}", ("play", str(i))))
                     for i in (1, 2))

    red, blue = TeamPlan(color="red", name="R", robots=robots("red")), TeamPlan(
        color="blue", name="B", robots=robots("blue"))
    ports = {t.color: {r.number: r.port for r in t.robots} for t in (red, blue)}
    return MatchPlan(
        match_id="g1", seed=3, red=red, blue=blue,
        spec_builder=lambda addresses, telemetry: match_spec(
            match_id="g1", seed=3, ports=ports, addresses=addresses, telemetry=telemetry),
        limits=Limits(cpus=1.0, memory_gb=1.0, team_api_mb_s=10.0, team_comm_mb_s=1.0),
        grace_period_s=3.0, telemetry=False,
    )


class GateWatchingHost(FakeHost):
    """Records, at each shaping, whether that robot's gate was open (its program running);
    ``fail_first``: the first shaping fails."""

    def __init__(self, out: Path, runtime: FakeRuntime, *, fail_first: bool = False) -> None:
        super().__init__()
        self.out = out
        self.runtime = runtime
        self.fail_first = fail_first
        self.open_at_shaping: dict[str, bool] = {}
        self.counter_reads = 0

    def shape(self, pid: int, shaping: RobotShaping) -> AppliedShaping | None:
        name = next(c.request.name for c in self.runtime.containers.values()
                    if c.state.pid == pid)
        key = name.removeprefix("hlvs-g1-")
        self.open_at_shaping[key] = (self.out / gate_mod.FOLDERS / key / gate_mod.GO).exists()
        if self.fail_first and not self.shaped:
            self.shaped.append(shaping)
            raise InfrastructureError("cannot apply bandwidth limits: no such device")
        return super().shape(pid, shaping)

    def counters(self, applied: AppliedShaping) -> TrafficCounters:
        self.counter_reads += 1
        return super().counters(applied)


class GateCheckingRuntime(FakeRuntime):
    """Keeps every container request; records, at each kill, whether the killed robot's gate
    was open."""

    def __init__(self, out: Path) -> None:
        super().__init__()
        self.out = out
        self.open_at_kill: dict[str, bool] = {}
        self.requests: dict[str, ContainerRequest] = {}

    def create_container(self, request: ContainerRequest) -> str:
        self.requests[request.name] = request
        return super().create_container(request)

    def kill(self, container_id: str) -> None:
        key = self.containers[container_id].request.name.removeprefix("hlvs-g1-")
        self.open_at_kill[key] = (self.out / gate_mod.FOLDERS / key / gate_mod.GO).exists()
        super().kill(container_id)


def _run(tmp_path: Path, runtime: GateCheckingRuntime, host: FakeHost,
         plan: MatchPlan | None = None
         ) -> MatchOutcome:
    return MatchRunner(plan or _plan(), runtime=runtime, host=host, options=RunOptions(
        out_dir=tmp_path, simulator_image="sim:1", poll_s=0.0, start_gate=GATE)).run()


def test_each_robot_is_one_container_on_its_network_behind_the_gate(tmp_path: Path) -> None:
    runtime = GateCheckingRuntime(tmp_path)
    runtime.image_launches["team/blue:1"] = (("/bin/robot", "--fast"), ("ignored",))
    host = GateWatchingHost(tmp_path, runtime)
    outcome = _run(tmp_path, runtime, host)
    assert outcome.ok, outcome.failure
    requests = runtime.requests
    assert not [n for n in requests if n.endswith("-net")]  # no holders
    red1 = requests["hlvs-g1-red-1"]
    assert red1.network_mode is None and red1.hostname == "red-1"
    assert [(a.network, a.ipv4_address, a.aliases) for a in red1.networks] == [
        ("hlvs-g1-red", red1.networks[0].ipv4_address, ("red-1",))]
    assert red1.networks[0].ipv4_address.endswith(".11")
    # the gate, its folder, then the image's entry point; the team's command as given
    assert red1.entrypoint == (gate_mod.TARGET, gate_mod.DIR_TARGET, "--", "/entrypoint.sh")
    assert red1.command == ("play", "1")
    assert requests["hlvs-g1-blue-2"].entrypoint == (
        gate_mod.TARGET, gate_mod.DIR_TARGET, "--", "/bin/robot", "--fast")
    gate_mounts = {m.target: m for m in red1.mounts if m.target.startswith("/.hlvs")}
    assert gate_mounts[gate_mod.TARGET].source == GATE
    assert gate_mounts[gate_mod.DIR_TARGET].source == tmp_path / gate_mod.FOLDERS / "red-1"
    assert all(m.read_only for m in gate_mounts.values())
    # every robot was shaped while its gate was closed, and its gate then opened
    assert host.open_at_shaping == dict.fromkeys(("red-1", "red-2", "blue-1", "blue-2"), False)
    results = json.loads((tmp_path / "results.json").read_text())
    for robot in results["robots"].values():
        assert robot["limits"]["api_rate_bit_s"] == 40_000_000  # 10 MB/s shared by two
        assert robot["sent_bytes"] == 110 and robot["received_bytes"] == 220
    assert host.counter_reads >= 4  # read as each robot was asked to stop
    assert not (tmp_path / gate_mod.FOLDERS).exists()  # the gates' folders are removed


def test_a_robot_whose_image_runs_nothing_is_not_started(tmp_path: Path) -> None:
    runtime = GateCheckingRuntime(tmp_path)
    runtime.image_launches["team/red:1"] = ((), ())
    outcome = _run(tmp_path, runtime, GateWatchingHost(tmp_path, runtime),
                   _plan({"red-1": None, "red-2": ("play",)}))
    results = json.loads((tmp_path / "results.json").read_text())
    red1 = results["robots"]["red-1"]
    assert "no entry point or command" in red1["startup_error"]
    assert "dockerCmd" in red1["startup_error"]
    assert results["robots"]["red-2"].get("startup_error") is None
    assert outcome.results is not None


def test_a_robot_that_cannot_be_shaped_is_killed_behind_its_gate(tmp_path: Path) -> None:
    runtime = GateCheckingRuntime(tmp_path)
    host = GateWatchingHost(tmp_path, runtime, fail_first=True)
    _run(tmp_path, runtime, host)
    results = json.loads((tmp_path / "results.json").read_text())
    failed = [k for k, r in results["robots"].items() if r.get("startup_error")]
    assert len(failed) == 1
    assert "cannot apply bandwidth limits" in results["robots"][failed[0]]["startup_error"]
    # killed at once, its gate still closed (the others were stopped at the end, not killed)
    assert runtime.open_at_kill == {failed[0]: False}


@pytest.mark.parametrize(("command", "image", "expected"), [
    (("a", "b"), (("/e",), ("c",)), (("/g", "--", "/e"), ("a", "b"))),
    (None, (("/e",), ("c",)), (("/g", "--", "/e"), ("c",))),
    ((), ((), ("/bin/run", "x")), (("/g", "--"), ("/bin/run", "x"))),
])
def test_gated_launch_joins_as_the_engine_does(
    command: tuple[str, ...] | None, image: tuple[tuple[str, ...], tuple[str, ...]],
    expected: tuple[tuple[str, ...], tuple[str, ...]],
) -> None:
    assert gate_mod.gated_launch(("/g", "--"), command, image) == expected
