"""The Referee facade: start-up placement, wall-clock waits, logs, game state and result."""

from __future__ import annotations

import json
import re
from dataclasses import replace
from pathlib import Path

from contracts.match_spec import GameType
from referee import FakeClock, PlaceBall, Referee, SetLimp, TeleportRobot
from referee.snapshot import RobotState
from tests.unit.referee.referee_helpers import FAST_TIMING, RED, make_config, robot, snapshot

LINE = re.compile(r"^\[\d{4}\.\d{3}\|\d{4}\.\d{3}\] (Info|Warning|Error): .+$")
STILL = (robot(RED, 1, -2.0, 0.5), robot(RED, 2, -1.0, -0.5))


def test_start_teleports_to_half_time_poses_and_places_ball() -> None:
    ref = Referee(config=make_config(side_left=RED), clock=FakeClock())
    commands = ref.step(snapshot(0, STILL))
    teleports = [c for c in commands if isinstance(c, TeleportRobot)]
    assert len(teleports) == 4
    red1 = next(t for t in teleports if str(t.robot) == "red player 1")
    blue1 = next(t for t in teleports if str(t.robot) == "blue player 1")
    assert (red1.pose.x_m, red1.pose.y_m) == (-1.5, -3.1)
    assert (blue1.pose.x_m, blue1.pose.y_m) == (1.5, -3.1)  # mirrored for the right side
    assert PlaceBall(position=(100.0, 100.0, 0.07)) in commands  # held off the field


def test_wall_clock_wait_before_first_ready() -> None:
    clock = FakeClock()
    timing = replace(FAST_TIMING, wait_before_first_ready_real_s=120.0)
    ref = Referee(config=make_config(timing=timing), clock=clock)
    ms = 0
    for _ in range(50):
        ref.step(snapshot(ms, STILL))
        ms += 8
    assert ref.waiting_for_wall_clock and ref.game_state["state"] == "INITIAL"
    clock.advance(119.0)
    ref.step(snapshot(ms, STILL))
    assert ref.waiting_for_wall_clock
    clock.advance(1.0)
    ref.step(snapshot(ms + 8, STILL))
    assert not ref.waiting_for_wall_clock and ref.game_state["state"] == "READY"
    assert ref.game_state["secs_remaining"] == 60  # the clock did not run while waiting


def _play(ref: Referee, clock: FakeClock, robots: tuple[RobotState, ...], limit_ms: int) -> int:
    """Steps the referee with robots that stand where it puts them (a penalised robot at its
    re-entry spot, not back on the field)."""
    ms = 0
    at = {r.id: r for r in robots}
    while not ref.finished and ms < limit_ms:
        for command in ref.step(snapshot(ms, tuple(at.values()))):
            assert isinstance(command, TeleportRobot | PlaceBall | SetLimp)
            if isinstance(command, TeleportRobot) and command.robot in at:
                pose = command.pose
                at[command.robot] = replace(at[command.robot], position=(pose.x_m, pose.y_m, 0.3))
        ms += 8
        clock.advance(0.008)
    return ms


def test_logs_and_result(tmp_path: Path) -> None:
    clock = FakeClock()
    timing = replace(FAST_TIMING, half_duration_s=30.0, status_period_real_s=20.0)
    ref = Referee(config=make_config(timing=timing), clock=clock, log_dir=tmp_path)
    _play(ref, clock, STILL, 100_000)
    ref.close()
    assert ref.finished
    result = ref.result()
    assert result["winner"] == "draw" and result["score"] == {"red": 0, "blue": 0}
    assert result["events_summary"]["game_over"] == 1  # type: ignore[index]
    human = (tmp_path / "referee.log").read_text().splitlines()
    assert human and all(LINE.match(line) for line in human), human[:3]
    assert any("STATUS: Avg speed factor: 1.000" in line for line in human)
    assert any(line.endswith("FINAL SCORE: 0-0") for line in human)
    events = [json.loads(x) for x in (tmp_path / "referee_events.jsonl").read_text().splitlines()]
    assert {"time", "type", "team", "player", "reason", "placement"} <= set(events[0])
    assert len(events) == len(ref.events)
    assert "state PLAYING" in (tmp_path / "gamecontroller.log").read_text()


def test_game_state_dict_for_telemetry() -> None:
    ref = Referee(config=make_config(), clock=FakeClock())
    ref.step(snapshot(0, STILL))
    state = ref.game_state
    assert {"state", "secondary_state", "half", "secs_remaining", "score", "penalties"} <= set(
        state
    )
    assert state["state"] == "READY" and state["score"] == {"red": 0, "blue": 0}


def test_penalty_game_result_has_shootout() -> None:
    clock = FakeClock()
    ref = Referee(config=make_config(game_type=GameType.PENALTY), clock=clock)
    _play(ref, clock, STILL, 200_000)
    result = ref.result()
    assert ref.finished and result["winner"] in ("red", "blue")
    assert result["coin_toss"] is True
    kicks = {"kicks": 10, "scored": 0}
    assert result["shootout"] == {"red": kicks, "blue": kicks}


def test_robot_missing_from_the_configuration_is_not_judged(tmp_path: Path) -> None:
    clock = FakeClock()
    timing = replace(FAST_TIMING, fallen_s=0.5)
    ref = Referee(config=make_config(timing=timing), clock=clock, log_dir=tmp_path)
    stranger = robot(RED, 9, -1.0, 0.0, fallen=True)
    for ms in range(0, 10_000, 8):
        ref.step(snapshot(ms, (*STILL, stranger)))
    ref.close()
    assert not [e for e in ref.events if e.type == "penalty" and e.player == 9]
    log = (tmp_path / "referee.log").read_text()
    assert log.count("red player 9 is not in the team configuration") == 1


def test_a_trainer_s_set_or_playing_puts_a_held_ball_on_the_centre_spot() -> None:
    """force_state: the ball held off the field before a kick-off goes on the centre spot for
    SET or PLAYING, as SET would put it; a ball on the field, or READY, is left where it is."""
    from referee import GameState

    ref = Referee(config=make_config(side_left=RED), clock=FakeClock())
    held = ref.step(snapshot(0, STILL))
    assert PlaceBall(position=(100.0, 100.0, 0.07)) in held
    away = snapshot(8, STILL, ball=(100.0, 100.0, 0.07))
    assert ref.force_state(GameState.READY, away) == []
    assert ref.force_state(GameState.SET, away) == [PlaceBall(position=(0.0, 0.0, 0.07))]
    assert ref.game_state["state"] == "SET" and not ref.waiting_for_wall_clock
    on_field = snapshot(16, STILL, ball=(1.0, -0.5, 0.07))
    assert ref.force_state(GameState.PLAYING, on_field) == []
    assert ref.game_state["state"] == "PLAYING"
