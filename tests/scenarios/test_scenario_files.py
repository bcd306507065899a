"""Scenario files are validated (errors name the file and the field) and runs are deterministic."""

from __future__ import annotations

from pathlib import Path

import pytest

from referee import ScenarioError
from tests.scenarios.driver import run_scenario
from tests.scenarios.scenario import load

ROOT = Path(__file__).parent


@pytest.mark.parametrize(
    ("text", "pointer", "reason"),
    [
        ("duration_s: 1\nexpect: []\n", "/expect", "must expect something"),
        ("duration_s: 1\nrobots: [{id: green-1, x: 0, y: 0}]\nexpect: [{no_event: {}}]\n",
         "/robots/0/id", "bad robot id"),
        ("duration_s: 1\nexpect: [{state: READY}]\n", "/expect/0", "need at_s"),
        ("duration_s: 1\nexpect: [{at_s: 1, colour: red}]\n", "/expect/0/colour", "unknown check"),
        ("duration_s: 1\nactions: [{at_s: 1}]\nexpect: [{no_event: {}}]\n", "/actions/0",
         "exactly one of"),
        ("duration_s: one\nexpect: [{no_event: {}}]\n", "/duration_s", "expected a number"),
        ("robots: 3\nduration_s: 1\nwhat: 1\n", "/what", "unknown key"),
    ],
)
def test_bad_scenario_files(tmp_path: Path, text: str, pointer: str, reason: str) -> None:
    path = tmp_path / "rule" / "case.yaml"
    path.parent.mkdir()
    path.write_text(text)
    with pytest.raises(ScenarioError) as info:
        load(path)
    assert info.value.path == str(path) and info.value.pointer == pointer
    assert reason in info.value.reason


def test_the_same_scenario_twice_gives_the_same_events() -> None:
    scenario = load(ROOT / "pushing" / "charging_near_ball_gives_free_kick.yaml")
    first, second = run_scenario(scenario), run_scenario(scenario)
    assert first.events and first.events == second.events
