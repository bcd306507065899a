"""The GameController's times and player slots on the wire, as the league's GameController
(Humanoid TC GameController, 2024-master) sends them: the clock paused through a set play, the
set play's secondary time, the removal penalty's 30 s, SUBSTITUTE slots, the half-time pause,
the send rate of a game not paced to real time, and exact seconds from integer time.

Each test names the league source lines it follows (``src/...`` of the GameController)."""

from __future__ import annotations

from dataclasses import replace

from contracts import TimingSpec, decode_game_state, send_period_s
from contracts.field import FieldClass
from contracts.gamecontroller import GameControlData
from contracts.ids import RobotId
from contracts.match_spec import GameType, MatchSpec
from referee import FakeClock, Referee
from referee.config import TimingConfig
from referee.gamecontroller import (
    Card,
    GameController,
    GameState,
    Penalty,
    SecondaryState,
    game_control_data,
)
from referee.logs import RefereeLog
from referee.publisher import Publisher
from simulator.match_setup import referee_config
from tests.unit.referee.referee_helpers import BLUE, FAST_TIMING, RED, make_config, robot, snapshot

TEAMS = {RED: 8, BLUE: 25}
SUBSTITUTE = int(Penalty.SUBSTITUTE)


def _gc(**timing: float) -> GameController:
    return GameController(
        game_type=GameType.NORMAL, players={RED: (1, 2), BLUE: (1, 2)}, kickoff=RED,
        timing=TimingConfig(**timing),
    )  # fmt: skip


def _playing(gc: GameController) -> GameController:
    for state in (GameState.READY, GameState.SET, GameState.PLAYING):
        gc.transition(state)
    return gc


def _wire(gc: GameController) -> GameControlData:
    return game_control_data(gc, team_numbers=TEAMS, players_per_team=4, packet_number=0,
                             left_team=RED)  # fmt: skip


def _run_ms(gc: GameController, ms: int, step_ms: int = 8) -> None:
    for _ in range(ms // step_ms):
        gc.advance_ms(step_ms)


def test_the_game_clock_and_the_penalties_stand_still_from_the_interruption_to_execute() -> None:
    """``GameInterruption.java:60``: the interruption performs ``ClockPause``, which stops the
    GameController's time (``ClockPause.java:40``, ``AdvancedData.java:193``: ``getTime``
    returns the moment of the pause); ``GameInterruption.java:81`` runs it again at EXECUTE.
    The game clock (``AdvancedData.java:298``) and the penalties (``:394``) read that time."""
    gc = _playing(_gc(half_duration_s=600.0))
    _run_ms(gc, 3000)
    robot_ = RobotId(BLUE, 2)
    gc.penalize(robot_, Penalty.PICKUP_OR_INCAPABLE)
    _run_ms(gc, 1000)
    assert (gc.wire_secs_remaining(), _wire(gc).teams[1].players[1].secs_till_unpenalised) == (
        596, 29)
    gc.begin_set_play(SecondaryState.THROW_IN, RED)
    executed = False
    for _ in range(25_000 // 8):  # 5 s + 15 s + 5 s of sub-phases
        tick = gc.advance_ms(8)
        executed = executed or tick.set_play_executed is not None
        if not executed:
            assert gc.wire_secs_remaining() == 596
            assert _wire(gc).teams[1].players[1].secs_till_unpenalised == 29
            assert not tick.unpenalised
    assert executed and gc.set_play is None and not gc.clock_paused
    _run_ms(gc, 1000)
    assert gc.wire_secs_remaining() == 595
    assert _wire(gc).teams[1].players[1].secs_till_unpenalised == 28


def test_an_aborted_set_play_runs_the_clock_again() -> None:
    """``AbortGameInterruption.java``: ABORT clears the secondary clock and performs
    ``ClockPause`` again, so the time runs on."""
    gc = _playing(_gc(half_duration_s=600.0))
    gc.begin_set_play(SecondaryState.GOAL_KICK, BLUE)
    _run_ms(gc, 2000)
    assert gc.wire_secs_remaining() == 600
    gc.abort_set_play()
    _run_ms(gc, 1000)
    assert gc.wire_secs_remaining() == 599


def test_secondary_time_is_zero_in_sub_phases_0_and_2_and_counts_in_1() -> None:
    """``GameInterruption.java:57``: the interruption sets no secondary clock (sub-phase 0);
    ``:68`` sets one of ``game_interruption_preparation_time`` (15 s, ``HLSim.java:114``) for
    sub-phase 1 and ``:72`` clears it for sub-phase 2; ``AdvancedData.java:424-425`` sends the
    secondary clock in a set play and ``:228-229`` 0 when there is none."""
    gc = _playing(_gc(set_play_phase0_s=5.0, set_play_ready_s=15.0, set_play_prepare_s=5.0))
    gc.begin_set_play(SecondaryState.THROW_IN, RED)
    seen: dict[int, set[int]] = {0: set(), 1: set(), 2: set()}
    for _ in range(25_000 // 8 - 1):
        gc.advance_ms(8)
        assert gc.set_play is not None
        data = _wire(gc)
        assert data.secondary_state_info[1] == gc.set_play.sub_phase
        seen[gc.set_play.sub_phase].add(data.secondary_time)
    assert seen[0] == {0} and seen[2] == {0}
    assert seen[1] == set(range(1, 16)), seen[1]  # 15..1, then sub-phase 2


def test_the_preparation_clock_starts_at_15_and_goes_below_zero_in_a_longer_phase() -> None:
    """``ExtraClock.java:25-26``: the secondary clock counts ``life_time`` less the whole
    seconds since it was set, on the simulated time (``SystemClock``), below zero when the
    sub-phase lasts longer (here the referee's penalty kick, twice 15 s)."""
    gc = _playing(_gc(set_play_phase0_s=1.0, set_play_ready_s=15.0))
    gc.begin_set_play(SecondaryState.PENALTYKICK, BLUE)
    _run_ms(gc, 1000)
    assert gc.set_play is not None and gc.set_play.sub_phase == 1
    assert _wire(gc).secondary_time == 15
    gc.advance_ms(999)
    assert _wire(gc).secondary_time == 15
    gc.advance_ms(1)
    assert _wire(gc).secondary_time == 14
    _run_ms(gc, 20_000)
    assert gc.set_play.sub_phase == 1 and _wire(gc).secondary_time == -6


def test_removal_penalty_lasts_30_s_by_default() -> None:
    """``Penalties.java:15-17``: ball manipulation, pushing and pick-up/incapable last 30 s
    (the league referee's ``REMOVAL_PENALTY_TIMEOUT`` too); ``AdvancedData.java:394`` counts
    them down in whole seconds and ``:241-243`` lifts them at 0."""
    assert TimingSpec().removal_penalty_s == 30.0 and TimingConfig().removal_penalty_s == 30.0
    gc = _playing(_gc())
    robot_ = RobotId(RED, 2)
    gc.penalize(robot_, Penalty.PHYSICAL_CONTACT)
    assert _wire(gc).teams[0].players[1].penalty == int(Penalty.PHYSICAL_CONTACT)
    assert _wire(gc).teams[0].players[1].secs_till_unpenalised == 30
    _run_ms(gc, 29_992)
    assert gc.robot(robot_).penalty is Penalty.PHYSICAL_CONTACT
    assert _wire(gc).teams[0].players[1].secs_till_unpenalised == 1
    assert gc.advance_ms(8).unpenalised == (robot_,)


def test_slots_past_the_leagues_players_per_team_are_substitutes() -> None:
    """``AdvancedData.java:143-146``: every slot from ``robotsPlaying`` on carries SUBSTITUTE;
    ``GameControlData.java:62``: ``playersPerTeam`` is ``teamSize``: 4 on the kid field
    (``HLSimulationKid.java:17-19``), 2 on the adult field (``HLSimulationAdult.java:17-19``).
    A slot of the league's count without a robot in the match has no penalty."""
    for field_class, count in ((FieldClass.KID, 4), (FieldClass.ADULT, 2)):
        config = replace(make_config(players=2), field_class=field_class)
        ref = Referee(config=config, clock=FakeClock())
        ref.step(snapshot(0, ()))
        data = decode_game_state(ref.packet())
        assert data.players_per_team == count
        for team in data.teams:
            penalties = [p.penalty for p in team.players]
            assert penalties == [0] * count + [SUBSTITUTE] * (11 - count), (field_class, penalties)
            assert all(p.secs_till_unpenalised == 0 for p in team.players)


def test_half_time_initial_counts_the_pause_below_zero() -> None:
    """``AdvancedData.java:309-312``: in the INITIAL before a second half the secondary time
    is ``pauseTime`` less the seconds since the half ended, and ``pauseTime`` is 0 in the
    simulation leagues (``HLSim.java:38``): 0, -1, -2... ``SecondHalf.java:44`` keeps the
    moment the half finished as the start of the pause."""
    clock = FakeClock()
    timing = replace(FAST_TIMING, half_duration_s=4.0, half_time_break_real_s=5.0)
    ref = Referee(config=make_config(timing=timing), clock=clock)
    robots = (robot(RED, 1, -2.0, 0.5), robot(BLUE, 1, 2.0, -0.5))
    ms, finished_ms = 0, None
    seen: list[tuple[int, int]] = []
    while ms < 20_000:
        ref.step(snapshot(ms, robots))
        data = decode_game_state(ref.packet())
        if finished_ms is None and not data.first_half:
            finished_ms = ms
        if data.state == int(GameState.INITIAL) and not data.first_half:
            assert finished_ms is not None
            seen.append((ms - finished_ms, data.secondary_time))
        ms += 8
        clock.advance(0.008)
    assert seen, "no half-time INITIAL"
    assert all(value == -(since // 1000) for since, value in seen), seen[::100]
    assert min(value for _, value in seen) <= -4  # a break of 5 s of wall (and simulated) time


def test_a_game_not_paced_to_real_time_sends_every_50_ms() -> None:
    """``GameControllerSimulator.java:386-387``: ``--fast`` sends every 50 ms, else
    ``Sender.java:63`` every 500 ms; the league's referee passes ``--fast`` when the real-time
    factor limit is <= 0 or above 1 (hlvs_webots ``referee.py:1949-1950``)."""
    assert [send_period_s(f) for f in (0.0, -1.0, 1.5, 1.0, 0.5)] == [0.05, 0.05, 0.05, 0.5, 0.5]
    config = make_config()
    for factor, rate in ((0.0, 20.0), (4.0, 20.0), (1.0, 2.0)):
        spec = MatchSpec(
            match_id="m", seed=1, game_type="NORMAL", field_class="kid", side_left="red",
            kickoff="red", red=config.red, blue=config.blue, maximum_real_time_factor=factor,
        )  # fmt: skip
        assert referee_config(spec).network.send_rate_hz == rate


def test_secs_remaining_is_exact_at_every_step_of_a_half() -> None:
    """``AdvancedData.java:282-300``: ``secsRemaining`` is the half less the whole seconds
    played, ``getSecondsSince`` truncating milliseconds (``:202``); never one second high."""
    gc = _playing(_gc(half_duration_s=600.0))
    played_ms = 0
    while played_ms < 600_000:
        gc.advance_ms(8)
        played_ms += 8
        assert gc.wire_secs_remaining() == 600 - played_ms // 1000, played_ms
    assert gc.wire_secs_remaining() == 0


def test_float_steps_of_the_referee_give_exact_seconds() -> None:
    """The same through ``advance`` in float seconds (0.008 s each, as a sum they drift)."""
    gc = _playing(_gc(half_duration_s=600.0))
    for step in range(1, 75_001):  # the old float sum read 1 s high from 269 s on
        gc.advance(0.008)
        assert gc.wire_secs_remaining() == 600 - (step * 8) // 1000, step


class _Network:
    def __init__(self) -> None:
        self.packets: list[bytes] = []

    def publish(self, packet: bytes, *, state_changed: bool = False) -> None:
        self.packets.append(packet)


def test_the_packet_handed_to_the_sender_follows_every_change_of_a_time() -> None:
    """``Sender.java:164``: the league computes the times when it sends (``updateTimes``);
    here the packet is rebuilt whenever a time on the wire changes, whatever the wall clock
    does (it stands still in this test)."""
    clock = FakeClock()
    gc = _playing(_gc(half_duration_s=600.0))
    publisher = Publisher(gc=gc, team_numbers=TEAMS, players_per_team=4, left_team=lambda: RED,
                          log=RefereeLog(clock=clock))  # fmt: skip
    network = _Network()
    publisher.network = network  # type: ignore[assignment]
    ms = 0
    for _ in range(5000 // 8):
        gc.advance_ms(8)
        ms += 8
        publisher.publish(ms)
        sent = decode_game_state(network.packets[-1])
        assert sent.secs_remaining == 600 - ms // 1000
        assert sent.secondary_time == max(0, 10 - ms // 1000)
    assert len(network.packets) == 1 + 5  # the first, then one at each whole second


def test_a_goalkeeper_or_a_card_is_handed_to_the_sender_while_the_clock_stands() -> None:
    """In INITIAL no time on the wire moves; a new goalkeeper and a warning still reach the
    packet the sender sends (``Sender.java:164`` sends the GameController's data as it is)."""
    clock = FakeClock()
    gc = _gc()
    publisher = Publisher(gc=gc, team_numbers=TEAMS, players_per_team=4, left_team=lambda: RED,
                          log=RefereeLog(clock=clock))  # fmt: skip
    network = _Network()
    publisher.network = network  # type: ignore[assignment]
    publisher.publish(0)
    gc.advance_ms(8)
    publisher.publish(8)
    assert len(network.packets) == 1  # nothing changed
    gc.set_goalkeeper(RobotId(RED, 2))
    publisher.publish(16)
    players = decode_game_state(network.packets[-1]).teams[0].players
    assert (players[0].goal_keeper, players[1].goal_keeper) == (False, True)
    gc.card(RobotId(BLUE, 1), Card.WARNING)
    publisher.publish(24)
    assert decode_game_state(network.packets[-1]).teams[1].players[0].number_of_warnings == 1
    assert len(network.packets) == 3
