"""Before a period's kick-off, as the league's referee does it: the ball held off the field in
INITIAL and READY (hlvs_webots referee.py:1756-1768, ``move_ball_away`` called by
``kickoff``), placed on the centre spot when SET begins; robots at their start positions
checked when READY begins (1212-1228, ``check_start_position``)."""

from __future__ import annotations

import math
from dataclasses import replace

import pytest

from contracts.field import KID_FIELD
from contracts.ids import RobotId
from referee import FakeClock, Referee
from referee.config import TimingConfig
from referee.gamecontroller import GameState, Penalty, SecondaryState
from referee.rules import kickoff
from referee.rules.base import GameView, PenalizeRobot
from referee.snapshot import PlaceBall, RobotState
from tests.unit.referee.referee_helpers import (
    BLUE,
    FAST_TIMING,
    RED,
    make_config,
    robot,
    snapshot,
)

WAIT = replace(FAST_TIMING, wait_before_first_ready_real_s=1.0)  # INITIAL for 1 s
AWAY = PlaceBall(position=(100.0, 100.0, KID_FIELD.ball_radius_m))
CENTRE = PlaceBall(position=(0.0, 0.0, KID_FIELD.ball_radius_m))


def _view() -> GameView:
    return GameView(
        state=GameState.READY, phase=SecondaryState.NORMAL, set_play=None, half=1,
        kickoff_team=RED, left_team=RED, ball_in_play=False, penalised=frozenset(),
        goalkeepers=frozenset(), field=KID_FIELD, timing=TimingConfig(),
    )  # fmt: skip


def test_the_ball_is_held_off_the_field_until_set_then_put_on_the_centre_spot() -> None:
    clock = FakeClock()
    ref = Referee(config=make_config(side_left=RED, timing=WAIT), clock=clock)
    start = (robot(RED, 1, -1.0, -3.2, hull=False), robot(BLUE, 1, 1.0, 3.2, hull=False))
    robots = (robot(RED, 1, -1.0, -1.0), robot(BLUE, 1, 1.0, 1.0))
    placed: list[tuple[GameState, object]] = []
    ball = (0.0, 0.0, 0.07)
    ms = 0
    while ref.gc.state is not GameState.PLAYING:
        at = start if ref.gc.state is GameState.INITIAL else robots
        for command in ref.step(snapshot(ms, at, ball=ball)):
            if isinstance(command, PlaceBall):
                placed.append((ref.gc.state, command))
                ball = command.position
        ms += 8
        clock.advance(0.008)
    assert placed == [(GameState.INITIAL, AWAY), (GameState.SET, CENTRE)]
    # after a goal: READY again, the ball held off the field until SET
    # out of the centre circle, kicked there by blue 1, into red's goal
    touch_ms: int | None = None
    for ball in ((0.0, 0.0, 0.07), (1.0, 0.0, 0.07), (0.9, 0.0, 0.07), (-4.8, 0.0, 0.07)):
        touch_ms = ms if ball[0] == 0.9 else touch_ms
        at = snapshot(ms, robots, ball=ball, toucher=RobotId(BLUE, 1) if touch_ms else None)
        commands = ref.step(replace(at, last_ball_touch_ms=touch_ms))
        ms += 8
    assert ref.game_state["state"] == "READY" and AWAY in commands


def test_start_positions_must_be_off_the_field_on_the_own_side() -> None:
    """The league's positioning/initial scenario (red on the left here): red 1 on the field,
    blue 2 on the wrong side of the halfway line (a foot beyond the middle of the line), red 2
    and blue 1 outside the field on their sides: fine."""
    red1 = robot(RED, 1, -2.0, -2.06)
    red2 = robot(RED, 2, -0.75, -3.1, hull=False)
    blue1 = robot(BLUE, 1, 4.7, -2.06, hull=False)
    blue2 = robot(BLUE, 2, 0.06, 3.1)  # its feet at x = 0.01: on the wrong side
    decisions = kickoff.judge_start(snapshot(0, (red1, red2, blue1, blue2)), _view())
    assert decisions == [
        PenalizeRobot(RobotId(RED, 1), Penalty.PICKUP_OR_INCAPABLE,
                      "halfTimeStartingPose inside the field"),
        PenalizeRobot(RobotId(BLUE, 2), Penalty.PICKUP_OR_INCAPABLE,
                      "halfTimeStartingPose outside its team's side"),
    ]  # fmt: skip
    on_line = robot(RED, 2, -0.75, -3.04)  # a hand or foot at y = -2.98: on the touch line
    assert [d.robot for d in kickoff.judge_start(snapshot(0, (on_line,)), _view())] == [  # type: ignore[union-attr]
        RobotId(RED, 2)
    ]


def test_a_toe_on_the_line_is_on_the_field() -> None:
    """The league reads the feet's contact points with the ground, the corners of its robots'
    foot boxes (hlvs_webots referee.py:686-770): its positioning/initial scenario's red 2 at
    y 3.02 facing the field and blue 2 at x -4.55 facing it have a toe on the line. Feet at
    the torso's x and y, soles 0.105 m long: the toes 0.0525 m in front."""
    sole = (-0.0525, 0.0525, -0.034, 0.034)

    def standing(number: int, x: float, y: float, yaw: float) -> RobotState:
        left = (x - 0.045 * math.sin(yaw), y + 0.045 * math.cos(yaw))
        right = (x + 0.045 * math.sin(yaw), y - 0.045 * math.cos(yaw))
        return replace(robot(BLUE, number, x, y), yaw_rad=yaw, sole_outline=sole,
                       hull_points=(left, right, left, right))  # fmt: skip

    toe_on_touch_line = standing(2, 4.0, 3.02, -math.pi / 2)
    corners = toe_on_touch_line.sole_corners()
    assert len(corners) == 8
    assert min(y for _, y in corners) == pytest.approx(3.02 - 0.0525)
    toe_on_goal_line = standing(3, 4.55, 2.06, math.pi)
    heel_on_touch_line = standing(4, 3.0, 3.0 + 0.0525 - 0.001, math.pi / 2)  # facing out
    clear = standing(1, 4.7, -2.06, math.pi)  # its toes at x 4.6475
    decisions = kickoff.judge_start(
        snapshot(0, (toe_on_touch_line, toe_on_goal_line, heel_on_touch_line, clear)), _view())
    assert [d.robot for d in decisions] == [  # type: ignore[union-attr]
        RobotId(BLUE, 2), RobotId(BLUE, 3), RobotId(BLUE, 4)]


def test_the_referee_checks_start_positions_when_ready_begins() -> None:
    clock = FakeClock()
    ref = Referee(config=make_config(side_left=RED, timing=WAIT), clock=clock)
    inside = (robot(RED, 1, -1.0, -1.0), robot(BLUE, 1, 1.0, 3.2, hull=False))
    ms = 0
    while ref.gc.state is GameState.INITIAL:
        ref.step(snapshot(ms, inside))
        ms += 8
        clock.advance(0.008)
    assert ref.gc.robot(RobotId(RED, 1)).penalty is Penalty.PICKUP_OR_INCAPABLE
    assert ref.gc.robot(RobotId(BLUE, 1)).penalty is Penalty.NONE
