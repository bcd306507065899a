"""``limits.robot_runtime`` (game.json): the robots, and only they, run under the engine's OCI
runtime of that name (gVisor's ``runsc``); without it, the engine's default."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path
from typing import Any

from orchestrator.config.game import _limits
from orchestrator.match.fake import FakeRuntime
from tests.unit.match.test_match_runner import _plan, _run


def _requests(tmp_path: Path, runtime_name: str) -> list[Any]:
    plan = _plan()
    plan = replace(plan, limits=replace(plan.limits, robot_runtime=runtime_name))
    runtime = FakeRuntime()
    seen: list[Any] = []
    runtime.on_start = lambda c: seen.append(c.request)
    _run(tmp_path, plan, runtime)
    return seen


def test_robots_run_under_the_league_runtime_and_nothing_else_does(tmp_path: Path) -> None:
    seen = _requests(tmp_path / "runsc", "runsc")
    robots = [r for r in seen if r.name.startswith("hlvs-u1-red-") or
              r.name.startswith("hlvs-u1-blue-")]
    robots = [r for r in robots if not r.name.endswith("-net")]
    assert len(robots) == 4 and all(r.runtime == "runsc" for r in robots)
    others = [r for r in seen if r not in robots]
    assert others and all(r.runtime is None for r in others)  # simulator, network holders
    default = _requests(tmp_path / "default", "")
    assert all(r.runtime is None for r in default)


def test_game_json_names_the_runtime_as_a_string() -> None:
    assert _limits({"robot_runtime": "runsc", "pids": 64}).robot_runtime == "runsc"
    assert _limits({}).robot_runtime == ""
