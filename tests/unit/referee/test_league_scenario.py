"""The league's test scenario format (referee.league_scenario) and its timing semantics
(simulator.league_tests.Status / is_active / is_finished), as hlvs_webots'
``controllers/test_supervisor/rc_testing.py`` defines them."""

from __future__ import annotations

from pathlib import Path

import pytest

from contracts import GameControlData, RobotId, TeamColor, TeamInfo
from referee import LeagueTiming, ScenarioError, parse_league_scenario
from simulator.league_tests import Status, is_active, is_finished

PATH = Path("case/test_scenario.json")


def scenario(timing: dict[str, object], **step: object) -> object:
    return [{"timing": timing, **step}]


def timing_of(raw: dict[str, object]) -> LeagueTiming:
    return parse_league_scenario(scenario(raw), path=PATH).steps[0].timing


def test_a_point_runs_once_after_its_time_and_an_interval_on_every_step_inside() -> None:
    """rc_testing.py:250-256 (TimeInterval: active in (start, end], finished after end) and
    270-276 (TimePoint: active and finished as soon as the time is passed)."""
    point, interval = timing_of({"time": 2.0}), timing_of({"time": [1, 3]})
    assert [is_active(point, t) for t in (None, 1.9, 2.0, 2.008)] == [False, False, False, True]
    assert is_finished(point, 2.008) and not is_finished(point, 2.0)
    assert [is_active(interval, t) for t in (1.0, 1.008, 3.0, 3.008)] == [False, True, True, False]
    assert not is_finished(interval, 3.0) and is_finished(interval, 3.008)


def gc(state: int, secondary: int = 0, phase: int = 0) -> GameControlData:
    teams = (TeamInfo(team_number=1, team_colour=1), TeamInfo(team_number=2, team_colour=0))
    return GameControlData(
        packet_number=0, players_per_team=4, game_type=0, state=state, first_half=True,
        kick_off_team=1, secondary_state=secondary, secondary_state_info=(1, phase, 0, 0),
        secs_remaining=600, secondary_time=0, teams=teams,
    )  # fmt: skip


def test_times_count_from_the_nth_time_a_state_or_a_set_play_phase_was_reached() -> None:
    """rc_testing.py:144-190: a state start is recorded when the game state changes, a secondary
    state start when the secondary state or its phase changes (one list per phase)."""
    status = Status()
    status.update(0.0, 0.0, gc(1))  # READY
    status.update(0.0, 45.0, gc(2))  # SET
    status.update(0.0, 50.0, gc(3))  # PLAYING
    status.update(0.0, 60.0, gc(3, secondary=9, phase=0))  # THROWIN phase 0
    status.update(0.0, 65.0, gc(3, secondary=9, phase=1))
    status.update(0.0, 70.0, gc(3))
    status.update(0.0, 80.0, gc(1))  # READY again (a goal)
    status.update(0.0, 81.5, gc(1))
    assert status.now(timing_of({"time": 1, "state": "READY"})) == 81.5
    assert status.now(timing_of({"time": 1, "state": "READY", "state_count": 2})) == 1.5
    assert status.now(timing_of({"time": 1, "state": "READY", "state_count": 3})) is None
    assert status.now(timing_of({"time": 1, "state": "FINISHED"})) is None
    phase1 = {"time": 1, "secondary_state": "THROWIN", "phase": 1}
    assert status.now(timing_of(phase1)) == 16.5
    assert status.now(timing_of({"time": 1})) == 81.5  # since the start
    system = timing_of({"time": 1, "state": "READY", "clock_type": "System"})
    assert status.now(system) == 0.0


def test_tests_keep_what_the_league_reads_and_list_what_it_ignores() -> None:
    raw = scenario(
        {"time": 1},
        tests=[{"name": "t", "target": "RED_PLAYER_2", "penalty": 34, "position": [1, 2, 0.24],
                "rotation": [0, 0, 1, 0], "secondary_team": 5, "critical": True}],
        actions=[{"target": "BALL", "velocity": [1, 0, 0]}],
    )  # fmt: skip
    step = parse_league_scenario(raw, path=PATH).steps[0]
    test = step.tests[0]
    assert test.target is not None and test.target.robot == RobotId(TeamColor.RED, 2)
    assert test.checks == {"penalty": 34, "position": (1.0, 2.0, 0.24)}
    assert test.critical and test.abs_tol == 0.03
    assert test.ignored == ("rotation", "secondary_team")
    assert step.actions[0].velocity == (1.0, 0.0, 0.0, 0.0, 0.0, 0.0)  # rc_testing.py:500-501


@pytest.mark.parametrize(
    ("raw", "pointer"),
    [
        (scenario({"time": 1, "state_count": 0, "state": "SET"}), "/0/timing/state_count"),
        (scenario({"time": 1, "clock_type": "Wall"}), "/0/timing/clock_type"),
        (scenario({"time": 1}, tests=[{"name": "s", "target": "RED", "penalty": 0}]),
         "/0/tests/0/target"),
        (scenario({"time": 1}, tests=[{"name": "s", "target": "BLUE_PLAYER_1", "score": 1.5}]),
         "/0/tests/0/score"),
        (scenario({"time": 1}, actions=[{"target": "RED", "position": [0, 0, 0]}]),
         "/0/actions/0/target"),
        (scenario({"time": 1}, actions=[{"target": "BALL", "orientation": [0, 0, 0, 1]}]),
         "/0/actions/0/orientation"),
        (scenario({"time": 1}, actions=[{"target": "BALL", "torque": [0, 0, 1]}]),
         "/0/actions/0/torque"),
    ],
)  # fmt: skip
def test_what_the_runner_cannot_play_names_the_field(raw: object, pointer: str) -> None:
    with pytest.raises(ScenarioError) as info:
        parse_league_scenario(raw, path=PATH)
    assert info.value.path == str(PATH) and info.value.pointer == pointer
