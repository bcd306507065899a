"""``limits.robot_runtime`` (game.json): the robots, and only they, run under the engine's OCI
runtime of that name (gVisor's ``runsc``); without it, the engine's default."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path
from typing import Any

import pytest

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


def _asking(runtime_name: str) -> Any:
    plan = _plan()
    return replace(plan, limits=replace(plan.limits, robot_runtime=runtime_name),
                   game_file="/srv/league/game.json")


def test_a_runtime_the_engine_lacks_is_refused_naming_the_setting_and_the_engine() -> None:
    from orchestrator.errors import ConfigError
    from orchestrator.match import check_robot_runtime

    with pytest.raises(ConfigError) as refused:
        check_robot_runtime(_asking("runsc"), engine="unix:///run/other.sock",
                            runtimes=lambda: ["runc", "io.containerd.runc.v2"])
    (problem,) = refused.value.problems
    assert (problem.file, problem.pointer) == ("/srv/league/game.json", "/limits/robot_runtime")
    text = str(refused.value)
    assert "'runsc'" in text and "unix:///run/other.sock" in text
    assert "io.containerd.runc.v2, runc" in text and "no container was started" in text


def test_a_runtime_the_engine_has_and_the_default_pass() -> None:
    from orchestrator.match import check_robot_runtime

    check_robot_runtime(_asking("runsc"), engine="e", runtimes=lambda: ["runc", "runsc"])
    asked: list[int] = []
    check_robot_runtime(_asking(""), engine="e", runtimes=lambda: asked.append(1) or [])
    assert asked == []  # the engine's default: the engine is not asked


def test_under_another_runtime_the_engine_limit_leaves_room_for_the_sandbox(
        tmp_path: Path) -> None:
    """runsc's own host tasks share the robot's pids cgroup: the engine's limit is the game's
    ``pids`` plus the sandbox's room under a runtime, the game's ``pids`` alone without one."""
    from orchestrator.match.layout import SANDBOX_PIDS

    pids = _plan().limits.pids
    for runtime_name, expected in (("runsc", pids + SANDBOX_PIDS), ("", pids)):
        seen = _requests(tmp_path / (runtime_name or "default"), runtime_name)
        robots = [r for r in seen if r.runtime == (runtime_name or None)
                  and r.name.startswith("hlvs-u1-red-") and not r.name.endswith("-net")]
        assert robots and all(r.pids_limit == expected for r in robots)
