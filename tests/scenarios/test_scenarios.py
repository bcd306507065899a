"""Every scenario under tests/scenarios/<rule>/<case>.yaml, in the real MuJoCo world."""

from __future__ import annotations

from pathlib import Path

import pytest

from tests.scenarios.driver import describe, run_scenario
from tests.scenarios.scenario import discover, load

ROOT = Path(__file__).parent
PATHS = discover(ROOT)


def test_there_are_enough_scenarios() -> None:
    rules = {p.parent.name for p in PATHS}
    assert len(PATHS) >= 40, len(PATHS)
    assert {"goal", "ball_out", "kickoff", "fallen", "pushing", "removal"} <= rules


@pytest.mark.parametrize("path", PATHS, ids=[f"{p.parent.name}/{p.stem}" for p in PATHS])
def test_scenario(path: Path) -> None:
    run = run_scenario(load(path))
    assert not run.failures, describe(run)
