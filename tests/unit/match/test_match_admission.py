"""Admission of a match against the host's CPUs and memory."""

from __future__ import annotations

import pytest

from orchestrator.config import Limits
from orchestrator.match import MatchPlan, RobotPlan, TeamPlan
from orchestrator.match.admission import AdmissionRefused, HostResources, admit


def _plan(robots: int, limits: Limits) -> MatchPlan:
    def team(color: str) -> TeamPlan:
        return TeamPlan(color=color, name=color, robots=tuple(
            RobotPlan(color=color, number=n, port=10000 + n, image="img")
            for n in range(1, robots + 1)))

    return MatchPlan(match_id="m", seed=1, red=team("red"), blue=team("blue"),
                     spec_builder=lambda a, t: {}, limits=limits)


def test_the_league_default_does_not_fit_a_small_host_and_is_refused_when_official() -> None:
    host = HostResources(cpus=2.0, memory_gb=24.0)
    plan = _plan(4, Limits())
    with pytest.raises(AdmissionRefused) as refused:
        admit(plan, host=host, official=True)
    text = str(refused.value)
    assert "CPUs needed 33 (robots' limits + simulator 1) > 2 available" in text
    assert "memory needed 130 GB" in text and "24.0 GB available" in text
    verdict = admit(plan, host=host, official=False)  # a scrimmage plays, with the warning
    assert not verdict.fits and "does not fit" in str(verdict.to_json()["warning"])


def test_a_match_that_fits_has_no_warning() -> None:
    verdict = admit(_plan(1, Limits(cpus=0.5, memory_gb=1)),
                    host=HostResources(cpus=2.0, memory_gb=8.0), official=True)
    assert verdict.fits and verdict.to_json()["warning"] is None
    assert verdict.to_json()["cpus"] == {"needed": 2.0, "available": 2.0}


@pytest.mark.parametrize(("cpus", "robot_cpus", "render_cpus", "simulator", "robots"), [
    (16, 8.0, 4, "0,1,2,3,4", "5,6,7,8,9,10,11,12,13,14,15"),  # spare CPUs: 4 more to render
    (4, 1.0, 4, "0,1,2", "3"),  # two spare CPUs after the simulator's and the robots' own
    (4, 2.5, 4, "0", "1,2,3"),  # 2.5 CPUs of limits take three whole CPUs: nothing spare
    (2, 2.0, 4, "0", "1"),  # the robots' CPU is never given to the cameras
    (16, 8.0, 0, "0", "1,2,3,4,5,6,7,8,9,10,11,12,13,14,15"),  # cameras on a GPU
])
def test_cameras_on_the_cpu_get_the_cpus_the_robots_leave_spare(
    monkeypatch: pytest.MonkeyPatch, cpus: int, robot_cpus: float, render_cpus: int,
    simulator: str, robots: str,
) -> None:
    import os

    from orchestrator.match.admission import cpu_sets

    monkeypatch.setattr(os, "sched_getaffinity", lambda _pid: set(range(cpus)))
    monkeypatch.delenv("DOCKER_HOST", raising=False)
    sets = cpu_sets(stepping="async", robot_cpus=robot_cpus, render_cpus=render_cpus)
    assert (sets.simulator, sets.robots) == (simulator, robots)
    assert cpu_sets(stepping="lockstep", robot_cpus=robot_cpus, render_cpus=render_cpus
                    ).simulator is None


def test_async_matches_give_the_simulator_cpus_of_its_own() -> None:
    import os

    from orchestrator.match.admission import cpu_sets

    allowed = sorted(os.sched_getaffinity(0))
    assert cpu_sets(stepping="lockstep") == cpu_sets(stepping="lockstep").__class__(
        simulator=None, robots=None)
    sets = cpu_sets(stepping="async")
    if len(allowed) < 2 or os.environ.get("DOCKER_HOST", "unix://")[:7] != "unix://":
        assert sets.simulator is None
        return
    assert sets.simulator == str(allowed[0])
    assert sets.robots == ",".join(map(str, allowed[1:]))
