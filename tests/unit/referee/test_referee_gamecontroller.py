"""The GameController state machine on simulated time."""

from __future__ import annotations

import pytest

from contracts.ids import RobotId, TeamColor
from contracts.match_spec import GameType
from referee import IllegalTransition
from referee.config import TimingConfig
from referee.gamecontroller import (
    Card,
    GameController,
    GameState,
    Penalty,
    SecondaryState,
    Tick,
)

RED, BLUE = TeamColor.RED, TeamColor.BLUE


def make(game_type: GameType = GameType.NORMAL, **timing: float) -> GameController:
    return GameController(
        game_type=game_type,
        players={RED: (1, 2, 3, 4), BLUE: (1, 2, 3, 4)},
        kickoff=RED,
        timing=TimingConfig(**timing),
    )


def run(gc: GameController, seconds: float, dt: float = 0.008) -> list[Tick]:
    ticks: list[Tick] = []
    for _ in range(round(seconds / dt)):
        ticks.append(gc.advance(dt))
    return ticks


@pytest.mark.parametrize(
    ("path", "bad"),
    [
        ((), GameState.PLAYING),
        ((), GameState.FINISHED),
        ((GameState.READY,), GameState.PLAYING),
        ((GameState.READY, GameState.SET), GameState.READY),
        ((GameState.READY, GameState.SET, GameState.PLAYING), GameState.INITIAL),
    ],
)
def test_illegal_transitions_are_rejected(path: tuple[GameState, ...], bad: GameState) -> None:
    gc = make()
    for state in path:
        gc.transition(state)
    with pytest.raises(IllegalTransition) as info:
        gc.transition(bad)
    assert info.value.requested == bad.name and info.value.current == gc.state.name


def test_ready_lasts_45_s_then_set_with_the_clock_stopped_before_the_first_kickoff() -> None:
    """League GameController (2024-master) ``AdvancedData.getRemainingGameTime``: in READY and
    SET with ``timeBeforeCurrentGameState == 0`` no time of the half has been played, so the
    clock stands still and the first PLAYING of the half starts with the full half."""
    gc = make(half_duration_s=600.0)
    gc.transition(GameState.READY)
    assert gc.secondary_time == 45.0
    ticks = run(gc, 44.9)
    assert gc.state is GameState.READY and not any(t.auto_set for t in ticks)
    run(gc, 0.2)
    assert gc.state.name == "SET"
    assert gc.secs_remaining == 600.0
    run(gc, 5.0)
    gc.transition(GameState.PLAYING)
    assert gc.secs_remaining == 600.0
    run(gc, 1.0)
    assert 598.99 < gc.secs_remaining < 599.01


def test_ready_and_set_after_a_goal_run_the_clock() -> None:
    """League GameController (2024-master) ``AdvancedData.getRemainingGameTime``: once time of
    the half was played (``timeBeforeCurrentGameState > 0``) READY and SET count as played, as
    they do after a goal (no added time, ``lostTime`` false in the HL rules)."""
    gc = make(half_duration_s=600.0, ready_duration_s=45.0)
    for state in (GameState.READY, GameState.SET, GameState.PLAYING):
        gc.transition(state)
    run(gc, 10.0)
    gc.goal(RED)
    run(gc, 45.0)  # READY, then SET by itself
    assert gc.state is GameState.SET
    run(gc, 5.0)
    assert 539.99 < gc.secs_remaining < 540.01


def test_every_period_starts_its_first_playing_with_its_full_time() -> None:
    """League GameController (2024-master) ``AdvancedData.getRemainingGameTime``:
    ``timeBeforeCurrentGameState`` is 0 again at the start of each period, so the second half
    and each overtime half stop the clock in READY and SET before their first kick-off too."""
    gc = make(GameType.KNOCKOUT, half_duration_s=60.0, overtime_half_duration_s=30.0,
              ready_duration_s=10.0)
    expected = (60.0, 60.0, 30.0, 30.0)
    for full in expected:
        gc.transition(GameState.READY)
        run(gc, 10.0)
        assert gc.state is GameState.SET
        run(gc, 5.0)
        gc.transition(GameState.PLAYING)
        assert gc.secs_remaining == full
        ticks = run(gc, full)
        assert any(t.period_over for t in ticks)
        gc.transition(GameState.FINISHED)
        gc.next_period()


def test_clock_stands_still_in_initial_and_finished() -> None:
    gc = make(half_duration_s=10.0)
    run(gc, 5.0)
    assert gc.secs_remaining == 10.0
    for state in (GameState.READY, GameState.SET, GameState.PLAYING):
        gc.transition(state)
    ticks = run(gc, 10.0)
    assert any(t.period_over for t in ticks)
    gc.transition(GameState.FINISHED)
    before = gc.secs_remaining
    run(gc, 3.0)
    assert gc.secs_remaining == before


def test_goal_scores_gives_kickoff_to_the_conceding_team() -> None:
    gc = make()
    for state in (GameState.READY, GameState.SET, GameState.PLAYING):
        gc.transition(state)
    gc.goal(RED)
    assert gc.score(RED) == 1 and gc.kickoff_team is BLUE and gc.state is GameState.READY


def test_penalty_timer_and_unpenalise() -> None:
    gc = make(removal_penalty_s=10.0)
    for state in (GameState.READY, GameState.SET, GameState.PLAYING):
        gc.transition(state)
    robot = RobotId(BLUE, 3)
    gc.penalize(robot, Penalty.PHYSICAL_CONTACT)
    assert gc.penalised() == (robot,)
    ticks = run(gc, 9.9)
    assert not any(t.unpenalised for t in ticks)
    ticks = run(gc, 0.2)
    assert any(t.unpenalised == (robot,) for t in ticks)
    assert gc.robot(robot).penalty is Penalty.NONE


def test_cards_escalate() -> None:
    gc = make()
    robot = RobotId(RED, 2)
    assert gc.card(robot, Card.WARNING) is Card.WARNING
    assert gc.card(robot, Card.WARNING) is Card.YELLOW
    assert (gc.robot(robot).warnings, gc.robot(robot).yellow_cards) == (0, 1)
    gc.penalize(robot, Penalty.PICKUP_OR_INCAPABLE)
    assert gc.card(robot, Card.YELLOW) is Card.RED
    info = gc.robot(robot)
    # CardIncrease.java:47-50: the second yellow card is counted back to 0 as it makes the red
    # one; the card leaves the penalty the referee sent (hlvs_webots referee.py:1438-1448)
    assert (info.yellow_cards, info.red_cards) == (0, 1)
    assert info.penalty is Penalty.PICKUP_OR_INCAPABLE


def test_play_lifts_every_penalty_but_substitute() -> None:
    """STATE:PLAY (hlvs_webots referee.py:2451-2452) makes the league's GameController lift
    every penalty, served or not (SimulatorUpdateComponent.java:337-346, resetPenalties)."""
    gc = make()
    gc.transition(GameState.READY)
    gc.transition(GameState.SET)
    removed, sent_off, spare = RobotId(RED, 2), RobotId(BLUE, 1), RobotId(BLUE, 2)
    gc.penalize(removed, Penalty.PICKUP_OR_INCAPABLE)
    gc.penalize(sent_off, Penalty.PICKUP_OR_INCAPABLE)
    gc.card(sent_off, Card.RED)
    gc.penalize(spare, Penalty.SUBSTITUTE)
    run(gc, 1.0)
    assert gc.play() == (removed, sent_off)
    assert gc.penalised() == (spare,)
    assert gc.robot(sent_off).red_cards == 1


def test_play_in_the_shootout_keeps_penalties() -> None:
    gc = make()
    gc.phase = SecondaryState.PENALTYSHOOT
    gc.transition(GameState.SET)
    robot = RobotId(RED, 2)
    gc.penalize(robot, Penalty.PICKUP_OR_INCAPABLE)
    assert gc.play() == ()
    assert gc.penalised() == (robot,)


def test_set_play_sub_phases_and_timing() -> None:
    gc = make(set_play_phase0_s=5.0, set_play_ready_s=15.0, set_play_prepare_s=5.0)
    for state in (GameState.READY, GameState.SET, GameState.PLAYING):
        gc.transition(state)
    gc.begin_set_play(SecondaryState.PENALTYKICK, BLUE)
    assert gc.secondary_state is SecondaryState.PENALTYKICK and gc.set_play.sub_phase == 0  # type: ignore[union-attr]
    run(gc, 5.01)
    assert gc.set_play is not None and gc.set_play.sub_phase == 1
    assert gc.secondary_time == pytest.approx(30.0, abs=0.02)  # penalty kick: twice the time
    run(gc, 30.0)
    assert gc.set_play is not None and gc.set_play.sub_phase == 2
    ticks = run(gc, 5.0)
    executed = [t.set_play_executed for t in ticks if t.set_play_executed]
    assert len(executed) == 1 and gc.secondary_state.name == "NORMAL"


def test_set_play_only_while_playing() -> None:
    gc = make()
    with pytest.raises(IllegalTransition):
        gc.begin_set_play(SecondaryState.THROW_IN, RED)
    with pytest.raises(ValueError):
        gc.begin_set_play(SecondaryState.OVERTIME, RED)


def test_periods_of_a_knockout_game() -> None:
    gc = make(GameType.KNOCKOUT, half_duration_s=600.0, overtime_half_duration_s=300.0)
    seen = []
    for _ in range(4):
        for state in (GameState.READY, GameState.SET, GameState.PLAYING, GameState.FINISHED):
            gc.transition(state)
        phase = gc.next_period()
        seen.append((phase, gc.half, gc.secs_remaining, gc.kickoff_team))
    assert seen == [
        (SecondaryState.NORMAL, 2, 600.0, BLUE),
        (SecondaryState.OVERTIME, 1, 300.0, RED),
        (SecondaryState.OVERTIME, 2, 300.0, BLUE),
        (SecondaryState.PENALTYSHOOT, 1, 60.0, RED),
    ]


def test_penalty_game_starts_with_the_shootout() -> None:
    gc = make(GameType.PENALTY)
    assert gc.phase is SecondaryState.PENALTYSHOOT
    gc.transition(GameState.SET)
    gc.transition(GameState.PLAYING)
    gc.shootout_kick(RED, True)
    gc.shootout_kick(RED, False)
    gc.shootout_kick(RED, True)
    assert gc.teams[RED].single_shots == 0b101 and gc.teams[RED].penalty_shots == 3
    assert gc.score(RED) == 2


def test_goalkeeper_flag_moves() -> None:
    gc = make()
    assert gc.goalkeeper(RED) == 1
    gc.set_goalkeeper(RobotId(RED, 3))
    assert gc.goalkeeper(RED) == 3 and not gc.robot(RobotId(RED, 1)).goalkeeper
