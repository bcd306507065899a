"""What the referee counts as football: halves reaching PLAYING, kicks, shots, goals, falls."""

from __future__ import annotations

from dataclasses import replace

import pytest

from contracts.field import KID_FIELD
from referee import FakeClock, Referee
from referee.gamecontroller import GameState, SecondaryState
from referee.play_stats import PlayTracker
from referee.rules.base import GameView
from referee.snapshot import RefereeEvent
from tests.unit.referee.referee_helpers import (
    BLUE,
    FAST_TIMING,
    RED,
    make_config,
    robot,
    snapshot,
)


def _view(state: GameState = GameState.PLAYING, *, half: int = 1) -> GameView:
    return GameView(
        state=state, phase=SecondaryState.NORMAL, set_play=None, half=half, kickoff_team=RED,
        left_team=RED, ball_in_play=True, penalised=frozenset(), goalkeepers=frozenset(),
        field=KID_FIELD, timing=FAST_TIMING,
    )


def _kick(tracker: PlayTracker, start_ms: int, *, at: tuple[float, float],
          velocity: tuple[float, float], view: GameView | None = None) -> None:
    """Red 1 touches a still ball at ``at``; 16 ms later it rolls with ``velocity``."""
    view = view or _view()
    ball = (at[0], at[1], 0.07)
    kicker = robot(RED, 1, at[0] - 0.2, at[1], ball_contact=True)
    tracker.observe(snapshot(start_ms, (robot(RED, 1, at[0] - 0.2, at[1]),), ball=ball), view)
    tracker.observe(snapshot(start_ms + 8, (kicker,), ball=ball), view)
    moving = (velocity[0], velocity[1], 0.0)
    tracker.observe(snapshot(start_ms + 24, (robot(RED, 1, at[0] - 0.2, at[1]),), ball=ball,
                             ball_velocity=moving), view)


def test_a_kick_towards_the_goal_between_the_posts_is_a_shot() -> None:
    tracker = PlayTracker()
    _kick(tracker, 0, at=(2.0, 0.5), velocity=(2.5, -0.2))  # red attacks x > 0
    stats = tracker.stats([])
    assert stats.kicks[RED] == 1 and stats.shots[RED] == 1 and stats.kicks[BLUE] == 0


@pytest.mark.parametrize(
    ("at", "velocity"),
    [((2.0, 0.5), (2.5, 1.5)),  # wide of the post
     ((2.0, 0.5), (-2.5, 0.0)),  # back towards the own goal
     ((-2.0, 0.0), (2.5, 0.0))],  # from farther than half the field
)
def test_kicks_that_are_not_shots(at: tuple[float, float], velocity: tuple[float, float]) -> None:
    tracker = PlayTracker()
    _kick(tracker, 0, at=at, velocity=velocity)
    stats = tracker.stats([])
    assert stats.kicks[RED] == 1 and stats.shots[RED] == 0


def test_walking_the_ball_along_is_not_a_kick_and_nothing_counts_outside_playing() -> None:
    tracker = PlayTracker()
    _kick(tracker, 0, at=(1.0, 0.0), velocity=(0.4, 0.0))  # a push at walking speed
    _kick(tracker, 1000, at=(1.0, 0.0), velocity=(3.0, 0.0), view=_view(GameState.READY))
    assert tracker.stats([]).kicks == {RED: 0, BLUE: 0}


def test_falls_count_once_per_fall_and_halves_reaching_playing() -> None:
    tracker = PlayTracker()
    # down, a flicker while getting up (the same fall), up for 1.5 s, down again
    states = [(0, False), (8, True), (16, True), (24, False), (32, True), (40, False),
              (1540, False), (1548, True)]
    for ms, fallen in states:
        tracker.observe(snapshot(ms, (robot(BLUE, 2, 1.0, 0.0, fallen=fallen),)),
                        _view(half=1 if ms < 100 else 2))
    stats = tracker.stats([])
    assert stats.falls == {RED: 0, BLUE: 2}
    assert stats.halves_playing == (1, 2) and stats.both_halves_playing is True
    assert stats.playing_s == pytest.approx(1.548)


def test_goals_and_own_goals_from_the_goal_events() -> None:
    events = [
        RefereeEvent(sim_time_ms=1, type="goal", team=RED, details={"own_goal": False}),
        RefereeEvent(sim_time_ms=2, type="goal", team=RED, details={"own_goal": True}),
        RefereeEvent(sim_time_ms=3, type="state", team=RED),
    ]
    stats = PlayTracker().stats(events)
    assert stats.goals == {RED: 2, BLUE: 0}
    assert stats.own_goals == {RED: 0, BLUE: 1}  # a blue player put it in the blue goal


def test_the_referee_result_carries_the_play_record() -> None:
    clock = FakeClock()
    timing = replace(FAST_TIMING, half_duration_s=10.0)
    ref = Referee(config=make_config(timing=timing), clock=clock)
    ms = 0
    still = (robot(RED, 1, -2.0, 0.5), robot(BLUE, 1, 2.0, -0.5))
    while not ref.finished and ms < 60_000:
        ref.step(snapshot(ms, still))
        ms += 8
        clock.advance(0.008)
    play = ref.result()["play"]
    assert isinstance(play, dict)
    assert play["halves_playing"] == [1, 2] and play["both_halves_playing"] is True
    assert play["kicks"] == {"red": 0, "blue": 0}
    assert 2 * 10.0 - 0.1 < play["playing_s"] <= 20.0  # READY and SET before kick-off: no clock
