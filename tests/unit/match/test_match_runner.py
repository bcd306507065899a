"""The runner's flow against in-memory fakes of the engine, the host and telemetry."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

from contracts.sim_result import SimResult
from contracts.telemetry import StateMessage
from orchestrator.config import Limits
from orchestrator.match import (
    FailureClass,
    MatchOutcome,
    MatchPlan,
    MatchRunner,
    MatchState,
    RobotPlan,
    RunOptions,
    TeamPlan,
)
from orchestrator.match.fake import FakeHost, FakeRuntime, FakeTelemetry
from testkit.specs import match_spec


def _plan(*, red_image: str = "team/red:1", blue_image: str = "team/blue:1", n: int = 2,
          telemetry: bool = False, silence_s: float = 30.0) -> MatchPlan:
    def robots(color: str, image: str) -> tuple[RobotPlan, ...]:
        base = 10000 if color == "red" else 10020
        return tuple(RobotPlan(color=color, number=i, port=base + i, image=image,
                               command=("start", str(i))) for i in range(1, n + 1))

    red = TeamPlan(color="red", name="R", robots=robots("red", red_image))
    blue = TeamPlan(color="blue", name="B", robots=robots("blue", blue_image))
    ports = {t.color: {r.number: r.port for r in t.robots} for t in (red, blue)}
    return MatchPlan(
        match_id="u1", seed=3, red=red, blue=blue,
        spec_builder=lambda addresses, telemetry: match_spec(
            match_id="u1", seed=3, ports=ports, addresses=addresses, telemetry=telemetry),
        limits=Limits(cpus=2.0, memory_gb=1.0, team_api_mb_s=10.0, team_comm_mb_s=1.0),
        grace_period_s=3.0, telemetry=telemetry, telemetry_silence_s=silence_s,
    )


def _run(tmp_path: Path, plan: MatchPlan, runtime: FakeRuntime, **kwargs: Any
         ) -> tuple[list[MatchState], MatchOutcome]:
    """The match's states (from PENDING, as its events tell them) and its outcome."""
    from orchestrator.match import StateChanged

    runner = MatchRunner(plan, runtime=runtime, host=FakeHost(),
                         options=RunOptions(out_dir=tmp_path, simulator_image="sim:1",
                                            poll_s=0.0), **kwargs)
    stream = runner.events.subscribe()
    outcome = runner.run()
    history = [MatchState.PENDING]
    while not stream.empty():
        if isinstance(event := stream.get(), StateChanged):
            history.append(event.state)
    return history, outcome


def test_success_writes_results_and_report_last(tmp_path: Path) -> None:
    runtime = FakeRuntime()
    history, outcome = _run(tmp_path, _plan(), runtime)
    assert outcome.ok
    assert history[-1] is MatchState.DONE
    assert json.loads((tmp_path / "report.json").read_text()) == {"status": "success"}
    results = json.loads((tmp_path / "results.json").read_text())
    assert results["score"] == {"red": 2, "blue": 1}
    robot = results["robots"]["red-2"]
    assert robot["limits"]["api_rate_bit_s"] == 40_000_000  # 10 MB/s over 2 robots
    assert robot["limits"]["comm_rate_bit_s"] == 4_000_000
    assert robot["sent_bytes"] == 110 and robot["received_bytes"] == 220
    assert robot["cpu_peak_percent"] == 150.0
    assert (tmp_path / "public/replay.hlvsrec").read_text() == "replay"
    assert (tmp_path / "teams/red/2/stdout.log").read_text().startswith("hlvs-u1-red-2")
    assert runtime.containers == {} and runtime.networks == {}
    spec = json.loads((tmp_path / "simulator/match_spec.json").read_text())
    assert spec["red"]["hosts"][1].endswith(".12")
    created = [name for call, name in runtime.calls if call == "create_container"]
    assert len(created) == 9 and "hlvs-u1-simulator" in created
    for key in ("red-1", "red-2", "blue-1", "blue-2"):  # shaped namespace before the robot
        assert created.index(f"hlvs-u1-{key}-net") < created.index(f"hlvs-u1-{key}")


def test_busy_subnets_are_skipped(tmp_path: Path) -> None:
    from orchestrator.match.layout import candidate_subnets

    first = str(candidate_subnets("u1/control")[0].network)
    runtime = FakeRuntime(busy_subnets=(first,))
    _, outcome = _run(tmp_path, _plan(), runtime)
    assert outcome.ok
    assert [c for c in runtime.calls if c == ("create_network", "hlvs-u1-control")] != []


def test_robot_requests_carry_environment_limits_and_no_privileges(tmp_path: Path) -> None:
    runtime = FakeRuntime()
    seen: list[Any] = []
    runtime.on_start = lambda c: seen.append(c.request)
    _run(tmp_path, _plan(), runtime)
    robot = next(r for r in seen if r.name == "hlvs-u1-blue-2")
    env = robot.environment
    assert env["ROBOCUP_ROBOT_ID"] == "2" and env["ROBOCUP_TEAM_COLOR"] == "blue"
    assert env["ROBOCUP_SIMULATOR_ADDR"] == f"{env['ROBOCUP_MIRROR_SERVER_IP']}:10022"
    assert set(k for k in env if k.startswith("ROBOCUP_TEAM_PLAYER")) == {
        "ROBOCUP_TEAM_PLAYER1_IP", "ROBOCUP_TEAM_PLAYER2_IP"}
    assert robot.command == ("start", "2")
    assert robot.nano_cpus == 2_000_000_000 and robot.mem_bytes == 1_000_000_000
    assert robot.cpu_period_us == 10_000
    assert robot.cap_drop == ("ALL",) and robot.security_opt == ("no-new-privileges",)
    assert robot.network_mode is not None and robot.network_mode.startswith("container:")
    assert [m.target for m in robot.mounts] == ["/robocup-logs", "/tmp", "/var/tmp", "/root"]
    assert robot.read_only and robot.tmpfs == {"/run": "size=16m,mode=755"}


def test_forfeit_when_a_team_has_no_usable_image(tmp_path: Path) -> None:
    runtime = FakeRuntime(missing_images=("team/blue:1",))
    history, outcome = _run(tmp_path, _plan(), runtime)
    assert outcome.ok
    assert outcome.results.forfeit.team == "blue"
    assert outcome.results.winner == "red"
    assert not [c for c in runtime.calls if c[0] == "create_container"]
    assert history == [MatchState.PENDING, MatchState.PULLING, MatchState.STOPPING,
                       MatchState.COLLECTING, MatchState.DONE]


def test_simulator_crash_is_a_simulator_failure(tmp_path: Path) -> None:
    runtime = FakeRuntime(simulator_exit_code=2)
    history, outcome = _run(tmp_path, _plan(), runtime)
    assert outcome.failure is not None
    assert outcome.failure.failure_class is FailureClass.SIMULATOR
    assert "code 2" in outcome.failure.cause
    report = json.loads((tmp_path / "report.json").read_text())
    assert report["failure_class"] == "simulator"
    assert history[-1] is MatchState.FAILED
    assert runtime.containers == {}


def test_game_not_finished_is_a_referee_failure(tmp_path: Path) -> None:
    runtime = FakeRuntime(sim_result=SimResult(
        match_id="u1", seed=3, state="PLAYING", score={"red": 0, "blue": 0}, winner=None))
    _, outcome = _run(tmp_path, _plan(), runtime)
    assert outcome.failure is not None
    assert outcome.failure.failure_class is FailureClass.REFEREE


def test_silent_telemetry_fails_the_match(tmp_path: Path) -> None:
    runtime = FakeRuntime(simulator_exit_code=None)
    now = [0.0]

    def clock() -> float:
        now[0] += 1.0
        return now[0]

    telemetry = FakeTelemetry([], clock=clock, silent=True)
    _, outcome = _run(tmp_path, _plan(telemetry=True, silence_s=5.0), runtime,
                      telemetry=lambda endpoint, match_id: telemetry, clock=clock)
    assert outcome.failure is not None
    assert outcome.failure.failure_class is FailureClass.SIMULATOR
    assert "telemetry silent" in outcome.failure.cause
    assert telemetry.closed


def _state(state: str, *connected: str) -> StateMessage:
    return StateMessage(sim_time_ms=0, real_time_factor=1.0, state=state, secondary_state=None,
                        half=1, secs_remaining=None, score=None, connected=connected,
                        stepping="lockstep", robots=None)


def test_telemetry_moves_waiting_to_playing_and_measures_bringup(tmp_path: Path) -> None:
    runtime = FakeRuntime(simulator_polls=6)
    clock_now = [0.0]

    def clock() -> float:
        clock_now[0] += 0.5
        return clock_now[0]

    states = [_state("INITIAL", "red-1"),
              _state("INITIAL", "red-1", "red-2", "blue-1", "blue-2"),
              _state("READY", "red-1", "red-2", "blue-1", "blue-2")]
    telemetry = FakeTelemetry(states, clock=clock)
    history, outcome = _run(tmp_path, _plan(telemetry=True), runtime,
                           telemetry=lambda endpoint, match_id: telemetry, clock=clock)
    assert outcome.ok
    assert outcome.bringup_s is not None and outcome.bringup_s > 0
    assert MatchState.PLAYING in history
    spec = json.loads((tmp_path / "simulator/match_spec.json").read_text())
    telemetry = spec["network"]["telemetry_listen"]
    assert telemetry.startswith("tcp/10.213.") and telemetry.endswith(":7447")


def test_robot_exit_mid_game_is_recorded_and_the_game_goes_on(tmp_path: Path) -> None:
    runtime = FakeRuntime(simulator_polls=8)

    def crash_red_1(container: Any) -> None:
        if container.request.name == "hlvs-u1-red-1":
            runtime.exit(container.state.id, 137, oom=True)

    runtime.on_start = crash_red_1
    _, outcome = _run(tmp_path, _plan(), runtime)
    assert outcome.ok
    robot = outcome.results.robots["red-1"]
    assert robot.oom_killed is True and robot.exit_code == 137
    assert outcome.results.robots["red-2"].oom_killed is False


def test_unexpected_error_still_tears_down_and_is_raised(tmp_path: Path) -> None:
    import pytest

    runtime = FakeRuntime()

    def explode(container: Any) -> None:
        if container.request.name == "hlvs-u1-blue-1":
            raise ValueError("bug")

    runtime.on_start = explode
    with pytest.raises(ValueError):
        _run(tmp_path, _plan(), runtime)
    assert runtime.containers == {} and runtime.networks == {}
    report = json.loads((tmp_path / "report.json").read_text())
    assert report["failure_class"] == "infrastructure" and "bug" in report["cause"]


def test_team_whose_robots_cannot_start_is_a_team_startup_failure(tmp_path: Path) -> None:
    from orchestrator.errors import InfrastructureError

    runtime = FakeRuntime()

    def refuse_red(container: Any) -> None:
        if container.request.name.startswith("hlvs-u1-red-") and "-net" not in \
                container.request.name:
            raise InfrastructureError("exec: start: executable file not found in $PATH")

    runtime.on_start = refuse_red
    history, outcome = _run(tmp_path, _plan(), runtime)
    assert outcome.failure is not None
    assert outcome.failure.failure_class is FailureClass.TEAM_STARTUP
    assert "red" in outcome.failure.cause and "executable file not found" in outcome.failure.cause
    assert MatchState.PLAYING not in history
    assert outcome.results.robots["red-1"].startup_error
    assert outcome.results.robots["blue-1"].startup_error is None
    assert runtime.containers == {} and runtime.networks == {}


def test_robot_environment_names_the_team_number_the_stub_reads() -> None:
    """``ROBOCUP_TEAM_ID`` (optional in the league, read by teams and by our stub to find their
    team in the GameController's packets) is the team's number from game.json."""
    import ipaddress

    from orchestrator.match.layout import Subnet, robot_environment
    from orchestrator.match.plan import RobotPlan
    from robot.stub.options import read_env

    robot = RobotPlan(color="blue", number=2, port=10022, image="img", team_id=13)
    subnet = Subnet(network=ipaddress.IPv4Network("10.213.7.0/24"))
    env = robot_environment(robot, team_net=subnet, player_count=2, gamecontroller_ip=None)
    assert env["ROBOCUP_TEAM_ID"] == "13"
    assert read_env(env).team_id == 13


def _events(tmp_path: Path, plan: MatchPlan, runtime: FakeRuntime, **kwargs: Any
            ) -> tuple[list[Any], MatchOutcome]:
    runner = MatchRunner(plan, runtime=runtime, host=FakeHost(),
                         options=RunOptions(out_dir=tmp_path, simulator_image="sim:1",
                                            poll_s=0.0), **kwargs)
    stream = runner.events.subscribe()
    outcome = runner.run()
    seen = []
    while not stream.empty():
        seen.append(stream.get())
    return seen, outcome


def test_events_tell_an_observer_the_states_bringup_and_the_end(tmp_path: Path) -> None:
    from orchestrator.match import AllConnected, MatchEnded, StateChanged

    clock_now = [0.0]

    def clock() -> float:
        clock_now[0] += 0.5
        return clock_now[0]

    states = [_state("INITIAL", "red-1", "red-2", "blue-1", "blue-2"),
              _state("READY", "red-1", "red-2", "blue-1", "blue-2")]
    telemetry = FakeTelemetry(states, clock=clock)
    seen, outcome = _events(tmp_path, _plan(telemetry=True), FakeRuntime(simulator_polls=6),
                            telemetry=lambda endpoint, match_id: telemetry, clock=clock)
    assert outcome.ok
    assert [e.state for e in seen if isinstance(e, StateChanged)] == [
        MatchState.PULLING, MatchState.STARTING, MatchState.WAITING, MatchState.PLAYING,
        MatchState.STOPPING, MatchState.COLLECTING, MatchState.DONE]
    connected = [e for e in seen if isinstance(e, AllConnected)]
    assert len(connected) == 1 and connected[0].bringup_s == outcome.bringup_s
    assert seen[-1] == MatchEnded(failure=None)


def test_events_name_the_robots_that_did_not_start_then_the_failure(tmp_path: Path) -> None:
    from orchestrator.errors import InfrastructureError
    from orchestrator.match import MatchEnded, MatchFailed, RobotNotStarted

    runtime = FakeRuntime()

    def refuse_red(container: Any) -> None:
        if container.request.name.startswith("hlvs-u1-red-") and "-net" not in \
                container.request.name:
            raise InfrastructureError("exec: start: executable file not found in $PATH")

    runtime.on_start = refuse_red
    seen, outcome = _events(tmp_path, _plan(), runtime)
    not_started = [e for e in seen if isinstance(e, RobotNotStarted)]
    assert sorted(e.key for e in not_started) == ["red-1", "red-2"]  # started in parallel
    assert all("executable file not found" in e.cause for e in not_started)
    failed = [i for i, e in enumerate(seen) if isinstance(e, MatchFailed)]
    assert len(failed) == 1 and failed[0] > seen.index(not_started[-1])
    assert seen[-1] == MatchEnded(failure=outcome.failure)
