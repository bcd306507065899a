"""Kick-off positions hold through SET: a robot that enters the opponents' half after SET began
is removed, as the league's referee checks positions on every step of SET (hlvs_webots
referee.py:2358-2365, check_kickoff_position), not only when SET begins."""

from __future__ import annotations

from contracts.ids import RobotId
from referee import FakeClock, Penalty, Referee
from referee.gamecontroller import GameState
from tests.unit.referee.referee_helpers import BLUE, RED, make_config, robot, snapshot

B1 = RobotId(BLUE, 1)


def test_a_robot_entering_the_opponents_half_during_set_is_removed() -> None:
    clock = FakeClock()
    ref = Referee(config=make_config(side_left=RED), clock=clock)
    red, blue_home = robot(RED, 1, -2.0, 0.0), robot(BLUE, 1, 2.0, -2.0)
    ms = 0
    while ref.gc.state is not GameState.SET:
        ref.step(snapshot(ms, (red, blue_home)))
        clock.advance(0.008)
        ms += 8
    for _ in range(50):  # 0.4 s of SET in its own half: nothing
        ref.step(snapshot(ms, (red, blue_home)))
        clock.advance(0.008)
        ms += 8
    assert ref.gc.state is GameState.SET and ref.gc.robot(B1).penalty is Penalty.NONE
    blue_over = robot(BLUE, 1, -0.13, -2.0)  # blue defends x > 0: over the halfway line
    ref.step(snapshot(ms, (red, blue_over)))
    assert ref.gc.state is GameState.SET
    assert ref.gc.robot(B1).penalty is Penalty.PICKUP_OR_INCAPABLE
    assert [e.reason for e in ref.events if e.type == "penalty"] == [
        "in the opponents' half at kick-off"
    ]
