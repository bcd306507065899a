"""GameController behaviour pinned to the league's GameController (Java, 2024) and referee:
TeamInfo order, secsRemaining in FINISHED, the half-time break spent in INITIAL."""

from __future__ import annotations

import socket
import time
from dataclasses import replace
from pathlib import Path

from contracts.gamecontroller import GameControlData, decode_game_state
from contracts.match_spec import GameType
from referee import FakeClock, Referee
from referee.config import NetworkConfig
from tests.unit.referee.referee_helpers import (
    BLUE,
    FAST_TIMING,
    RED,
    make_config,
    robot,
    snapshot,
)

STILL = (robot(RED, 1, -2.0, 0.5), robot(BLUE, 1, 2.0, -0.5))
INITIAL, READY, PLAYING, FINISHED = 0, 1, 3, 4
RED_ID, BLUE_ID = 8, 25  # team numbers of make_config


def _packet(ref: Referee) -> GameControlData:
    return decode_game_state(ref.packet(), peer="test")


def _play(ref: Referee, clock: FakeClock, until_ms: int, start_ms: int = 0) -> list[
    tuple[int, GameControlData]
]:
    """Step every 8 ms (wall clock along) and keep each packet that differs from the last."""
    seen: list[tuple[int, GameControlData]] = []
    ms = start_ms
    while ms < until_ms and not ref.finished:
        ref.step(snapshot(ms, STILL))
        data = _packet(ref)
        last = seen[-1][1] if seen else None
        if last is None or (data.state, data.first_half, data.teams[0].team_number) != (
            last.state, last.first_half, last.teams[0].team_number
        ):
            seen.append((ms, data))
        ms += 8
        clock.advance(0.008)
    return seen


def test_team_playing_on_the_left_comes_first_and_swaps_at_half_time() -> None:
    clock = FakeClock()
    timing = replace(FAST_TIMING, half_duration_s=10.0, half_time_break_real_s=2.0)
    ref = Referee(config=make_config(side_left=BLUE, timing=timing), clock=clock)
    seen = _play(ref, clock, 60_000)
    first = next(d for _, d in seen if d.state == PLAYING and d.first_half)
    second = next(d for _, d in seen if d.state == PLAYING and not d.first_half)
    assert [t.team_number for t in first.teams] == [BLUE_ID, RED_ID]
    assert [t.team_colour for t in first.teams] == [0, 1]  # colours stay with the teams
    assert [t.team_number for t in second.teams] == [RED_ID, BLUE_ID]
    assert [t.team_colour for t in second.teams] == [1, 0]


def test_secs_remaining_is_zero_in_finished() -> None:
    clock = FakeClock()
    timing = replace(FAST_TIMING, half_duration_s=10.0)
    ref = Referee(config=make_config(timing=timing), clock=clock)
    _play(ref, clock, 60_000)
    assert ref.finished
    data = _packet(ref)
    assert data.state == FINISHED and data.secs_remaining == 0
    assert ref.game_state["secs_remaining"] == 0


def test_half_time_break_is_spent_in_initial_of_the_second_half() -> None:
    clock = FakeClock()
    timing = replace(FAST_TIMING, half_duration_s=10.0, half_time_break_real_s=15.0)
    ref = Referee(config=make_config(timing=timing), clock=clock)
    # READY (5 s) and SET (1 s) before the kick-off stop the clock: the half ends at 16 s
    seen = _play(ref, clock, 16_500)
    states = [(d.state, d.first_half) for _, d in seen]
    assert states[-1] == (INITIAL, False), states  # firstHalf 0 during the break
    assert ref.waiting_for_wall_clock
    assert _packet(ref).secs_remaining == 10  # the second half's clock, not yet running
    break_events = [(e.reason, e.details["half"]) for e in ref.events if e.type == "state"]
    assert break_events[-2:] == [("FINISHED", 1), ("INITIAL", 2)]
    seen = _play(ref, clock, 33_000, start_ms=16_500)  # past the 15 s of wall clock
    after = [(d.state, d.first_half) for _, d in seen]
    assert after[0] == (INITIAL, False) and (READY, False) in after, after
    ready_ms = next(ms for ms, d in seen if d.state == READY)
    assert ready_ms - 16_000 >= 15_000 - 500  # READY only after the 15 s break


def test_break_before_a_penalty_shootout_is_spent_in_initial_too() -> None:
    clock = FakeClock()
    timing = replace(FAST_TIMING, half_duration_s=4.0, overtime_half_duration_s=2.0,
                     half_time_break_real_s=3.0)
    ref = Referee(config=make_config(game_type=GameType.KNOCKOUT, timing=timing), clock=clock)
    _play(ref, clock, 200_000)
    states = [(e.reason, e.details["phase"]) for e in ref.events if e.type == "state"]
    before_shootout = states.index(("INITIAL", "PENALTYSHOOT"))
    assert states[before_shootout - 1] == ("FINISHED", "OVERTIME")


def test_robots_receive_finished_then_initial_of_the_second_half(tmp_path: Path) -> None:
    """Over real UDP: FINISHED lasts one step before the break's INITIAL, and still goes out
    (the league's referee commands the next period only once the GameController broadcast
    FINISHED, ``referee.py``)."""
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as listener:
        listener.bind(("127.0.0.2", 0))
        listener.settimeout(0.05)
        port = listener.getsockname()[1]
        config = replace(
            make_config(
                addresses={RED: ("127.0.0.2",)},
                timing=replace(FAST_TIMING, half_duration_s=3.0, half_time_break_real_s=30.0),
            ),
            network=NetworkConfig(bind_host="127.0.0.1", gc_data_port=port, gc_return_port=0,
                                  mirror_port=0),
        )
        clock = FakeClock()
        ref = Referee(config=config, clock=clock, log_dir=tmp_path)
        ref.start_network()
        try:
            _play(ref, clock, 9_500)  # READY 5 s and SET 1 s, then 3 s of PLAYING
            assert ref.waiting_for_wall_clock
            seen: list[tuple[int, bool]] = []
            deadline = time.monotonic() + 5.0
            while (INITIAL, False) not in seen and time.monotonic() < deadline:
                try:
                    raw, _ = listener.recvfrom(4096)
                except TimeoutError:
                    continue
                data = decode_game_state(raw, peer="test")
                if not seen or seen[-1] != (data.state, data.first_half):
                    seen.append((data.state, data.first_half))
        finally:
            ref.close()
    assert seen[-2:] == [(FINISHED, True), (INITIAL, False)], seen
