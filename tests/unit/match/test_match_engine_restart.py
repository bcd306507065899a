"""The Docker engine stopped or restarted mid-match, against the in-memory engine: the match
fails naming the engine (not the simulator it stopped), the engine is waited for, the consoles
it still holds are collected and everything of the match is removed; an engine that does not
come back leaves the match's objects, named with the command that removes them. The real
engine's case: ``tests/integration/faults/test_fault_engine_restart.py``."""

from __future__ import annotations

import json
from pathlib import Path

from orchestrator.errors import EngineLost
from orchestrator.match import FailureClass, MatchOutcome, MatchRunner, RunOptions
from orchestrator.match.fake import FakeHost, FakeRuntime
from orchestrator.runtime.port import ContainerState
from tests.unit.match.test_match_runner import _plan


class _RestartingEngine(FakeRuntime):
    """Restarts (:meth:`FakeRuntime.restart_engine`) at the simulator's third inspection,
    down for ``down_for_pings`` pings; with ``at_stop``, at the first stop instead (the
    simulator having ended by itself with code 137 just before)."""

    def __init__(self, *, down_for_pings: int, at_stop: bool = False) -> None:
        super().__init__(simulator_exit_code=137 if at_stop else None, simulator_polls=3)
        self.pings = down_for_pings
        self.at_stop = at_stop
        self.simulator_seen = 0

    def inspect(self, container_id: str) -> ContainerState:
        found = self.containers.get(container_id)
        if (not self.at_stop and found is not None and self.down_for == 0
                and found.request.labels.get("org.hlvs-runner.role") == "simulator"):
            self.simulator_seen += 1
            if self.simulator_seen == 3:
                self.restart_engine(down_for_pings=self.pings)
        return super().inspect(container_id)

    def stop(self, container_id: str, *, timeout_s: float) -> None:
        if self.at_stop:
            self.at_stop = False
            self.restart_engine(down_for_pings=self.pings)
        super().stop(container_id, timeout_s=timeout_s)


def _play(tmp_path: Path, runtime: FakeRuntime, *, engine_wait_s: float = 5.0) -> MatchOutcome:
    return MatchRunner(_plan(), runtime=runtime, host=FakeHost(), options=RunOptions(
        out_dir=tmp_path, simulator_image="sim:1", poll_s=0.0, engine_wait_s=engine_wait_s,
    )).run()


def _report(tmp_path: Path) -> dict[str, str]:
    report: dict[str, str] = json.loads((tmp_path / "report.json").read_text())
    return report


def test_an_engine_restarted_fast_is_named_and_the_match_cleaned(tmp_path: Path) -> None:
    """Back before the runner saw it gone: the simulator ended with code 137 and so did the
    network holders, which never end by themselves; before, the simulator was blamed."""
    runtime = _RestartingEngine(down_for_pings=0)
    outcome = _play(tmp_path, runtime)
    assert outcome.failure is not None
    assert outcome.failure.failure_class is FailureClass.INFRASTRUCTURE, outcome.failure
    cause = outcome.failure.cause
    assert "the Docker engine at fake://engine stopped the match's containers" in cause, cause
    assert "the simulator ended with code 137" in cause and "network holder" in cause
    assert _report(tmp_path) == {"status": "failed", "failure_class": "infrastructure",
                                 "cause": cause}
    assert runtime.containers == {} and runtime.networks == {}
    assert (tmp_path / "teams/red/1/stdout.log").read_text().startswith("hlvs-u1-red-1 stdout")


def test_an_engine_down_a_while_is_waited_for_then_everything_collected(tmp_path: Path) -> None:
    runtime = _RestartingEngine(down_for_pings=3)
    outcome = _play(tmp_path, runtime)
    assert outcome.failure is not None
    assert outcome.failure.failure_class is FailureClass.INFRASTRUCTURE
    assert "the Docker engine at fake://engine stopped answering" in outcome.failure.cause
    assert runtime.down_for == 0  # every failing ping was waited through
    assert runtime.containers == {} and runtime.networks == {}
    for robot in ("red/1", "red/2", "blue/1", "blue/2"):
        assert (tmp_path / "teams" / robot / "stdout.log").is_file(), robot
    results = json.loads((tmp_path / "results.json").read_text())
    assert results["failure"]["class"] == "infrastructure"


def test_a_simulator_ended_as_the_engine_went_down_is_not_blamed(tmp_path: Path) -> None:
    """The simulator's exit seen while the engine still answered (it stops every container
    before it closes its socket); the engine found gone in collection takes the blame."""
    runtime = _RestartingEngine(down_for_pings=2, at_stop=True)
    outcome = _play(tmp_path, runtime)
    assert outcome.failure is not None
    assert outcome.failure.failure_class is FailureClass.INFRASTRUCTURE, outcome.failure
    cause = outcome.failure.cause
    assert cause.startswith("the Docker engine at fake://engine stopped answering"), cause
    assert "simulator exited with code 137" in cause, cause
    assert runtime.containers == {} and runtime.networks == {}


def test_an_engine_that_does_not_come_back_leaves_the_match_named(tmp_path: Path) -> None:
    runtime = _RestartingEngine(down_for_pings=10**9)
    outcome = _play(tmp_path, runtime, engine_wait_s=0.2)
    assert outcome.failure is not None
    cause = outcome.failure.cause
    assert "stopped answering" in cause and "did not answer again within 0 s" in cause, cause
    assert "`hlvs cleanup --match u1` removes them once it answers" in cause
    assert _report(tmp_path)["cause"] == cause
    assert runtime.containers and runtime.networks  # left on the engine, as the cause says


def test_the_fake_engine_refuses_every_call_while_down() -> None:
    runtime = FakeRuntime()
    runtime.restart_engine(down_for_pings=1)
    try:
        runtime.list_project()
    except EngineLost as exc:
        assert "fake://engine" in str(exc)
    else:
        raise AssertionError("a call to an engine that is down answered")
    assert runtime.answering() is False and runtime.answering() is True


def test_behind_the_start_gate_a_simulator_ended_by_a_signal_names_the_engine(
        tmp_path: Path) -> None:
    """No holders to look at: the simulator's own exit by a stop signal (137 here, not OOM)
    says that something outside the runner stopped it."""
    runtime = _RestartingEngine(down_for_pings=0)
    outcome = MatchRunner(_plan(), runtime=runtime, host=FakeHost(), options=RunOptions(
        out_dir=tmp_path, simulator_image="sim:1", poll_s=0.0, engine_wait_s=5.0,
        start_gate=Path("/opt/gate/start_gate"),
    )).run()
    assert outcome.failure is not None
    assert outcome.failure.failure_class is FailureClass.INFRASTRUCTURE, outcome.failure
    cause = outcome.failure.cause
    assert "the Docker engine at fake://engine stopped the match's containers" in cause, cause
    assert "the simulator ended by a signal (code 137)" in cause, cause


def test_behind_the_start_gate_a_simulator_that_fails_by_itself_is_blamed(
        tmp_path: Path) -> None:
    runtime = FakeRuntime(simulator_exit_code=1, simulator_polls=2)
    outcome = MatchRunner(_plan(), runtime=runtime, host=FakeHost(), options=RunOptions(
        out_dir=tmp_path, simulator_image="sim:1", poll_s=0.0,
        start_gate=Path("/opt/gate/start_gate"),
    )).run()
    assert outcome.failure is not None
    assert outcome.failure.failure_class is FailureClass.SIMULATOR, outcome.failure
    assert outcome.failure.cause.startswith("simulator exited with code 1"), outcome.failure
