"""The phases on their own, through their typed boundary: :func:`start` fills the ledger it is
given and returns a :class:`StartedMatch`; :func:`collect` turns a :class:`Played` record and
that ledger into the results, removing exactly what the ledger holds."""

from __future__ import annotations

import json
from dataclasses import replace
from pathlib import Path

import pytest

from contracts import RobotResult
from orchestrator.errors import InfrastructureError, OrchestratorError
from orchestrator.match import EventStream, FailureClass, MatchFailed, MatchState, RobotRecord
from orchestrator.match.collection import Played, collect
from orchestrator.match.deps import MatchDeps, RunOptions
from orchestrator.match.fake import FakeContainer, FakeHost, FakeRuntime
from orchestrator.match.monitor import StatsMonitor
from orchestrator.match.startup import Created, start
from orchestrator.match.state import Lifecycle
from tests.unit.match.test_match_runner import _plan


def _deps(tmp_path: Path, runtime: FakeRuntime, host: FakeHost) -> MatchDeps:
    ticks = iter(range(1_000_000))
    return MatchDeps(
        plan=_plan(), runtime=runtime, host=host,
        options=RunOptions(out_dir=tmp_path, simulator_image="sim:1", poll_s=0.0),
        clock=lambda: float(next(ticks)), events=EventStream(), monitor=StatsMonitor(runtime),
    )


def _robots(deps: MatchDeps) -> dict[str, RobotRecord]:
    return {r.key: RobotRecord(key=r.key, color=r.color, number=r.number,
                               entry=RobotResult(image=r.image, digest=f"sha256:{r.key}"))
            for r in deps.plan.robots}


def _starting(deps: MatchDeps) -> Lifecycle:
    lifecycle = Lifecycle(deps.plan.match_id, clock=deps.clock)
    lifecycle.advance(MatchState.PULLING)
    lifecycle.advance(MatchState.STARTING)
    return lifecycle


def test_collect_turns_a_played_record_into_the_results(tmp_path: Path) -> None:
    runtime, host = FakeRuntime(simulator_polls=1), FakeHost()
    deps = _deps(tmp_path, runtime, host)
    lifecycle, created, robots = _starting(deps), Created(), _robots(deps)
    started = start(deps, created, robots, deps.clock())
    assert started.failure is None and started.telemetry is None
    assert sorted(started.robot_ids) == ["blue-1", "blue-2", "red-1", "red-2"]
    assert started.simulator_id == created.simulator_id
    assert sorted(created.networks) == ["blue", "control", "red"]
    assert set(started.times.phases_s) == {"networks", "firewall", "spec", "simulator",
                                           "containers"}
    assert robots["red-2"].entry.container == "hlvs-u1-red-2"  # filled in as it started
    # the game: red 1 is killed for its memory, then the simulator ends it
    runtime.exit(started.robot_ids["red-1"], 137, oom=True)
    assert runtime.inspect(started.simulator_id).exited
    played = Played(
        robots={**robots, "red-1": replace(robots["red-1"], entry=replace(
            robots["red-1"].entry, exited_during_game=True, exit_code=137, oom_killed=True))},
        failure=None, forfeit=None, bringup_s=1.5,
    )
    results = collect(deps, lifecycle, created, played)
    assert results.status == "success" and results.failure is None
    assert results.score == {"red": 2, "blue": 1} and results.bringup_s == 1.5
    red1, red2 = results.robots["red-1"], results.robots["red-2"]
    assert red1.exited_during_game and red1.oom_killed and red1.exit_code == 137
    assert red2.sent_bytes == 110 and red2.cpu_peak_percent == 150.0
    assert played.robots["red-2"].entry.sent_bytes is None  # what it was given is left as it was
    assert lifecycle.state is MatchState.DONE
    assert set(results.timings_s) >= {"pulling", "starting", "stopping", "collecting"}
    assert runtime.containers == {} and runtime.networks == {} and host.isolated == []
    assert json.loads((tmp_path / "report.json").read_text()) == {"status": "success"}


def test_a_start_that_raises_half_way_leaves_a_ledger_that_collect_clears(
    tmp_path: Path,
) -> None:
    runtime, host = FakeRuntime(), FakeHost()

    def refuse_simulator(container: FakeContainer) -> None:
        if container.request.name == "hlvs-u1-simulator":
            raise InfrastructureError("engine refused the simulator")

    runtime.on_start = refuse_simulator
    deps = _deps(tmp_path, runtime, host)
    events = deps.events.subscribe()
    lifecycle, created = _starting(deps), Created()
    with pytest.raises(OrchestratorError) as raised:
        start(deps, created, _robots(deps), deps.clock())
    assert created.simulator_id is not None and len(created.networks) == 3
    assert len(created.robot_ids) == 4 and len(created.scratch) == 4
    failure = deps.fail(None, FailureClass.INFRASTRUCTURE, str(raised.value))
    results = collect(deps, lifecycle, created,
                      Played(robots=_robots(deps), failure=failure, forfeit=None, bringup_s=None))
    assert results.failure == failure
    assert lifecycle.state is MatchState.FAILED
    assert runtime.containers == {} and runtime.networks == {} and host.isolated == []
    assert sorted(host.released_folders) == sorted(f.path for f in created.scratch.values())
    seen = [events.get_nowait() for _ in range(events.qsize())]
    assert [e for e in seen if isinstance(e, MatchFailed)] == [MatchFailed(failure=failure)]
