"""Whole 2 x 600 s games with the default league timing, on the lightweight snapshot source
(tests/scenarios/kinematic.py): MuJoCo is too slow for 1200 s of simulated time in a test."""

from __future__ import annotations

from collections.abc import Callable

import pytest

from contracts.ids import RobotId, TeamColor
from referee import FakeClock, Referee, RefereeConfig, TimingConfig
from tests.scenarios.kinematic import KinematicWorld
from tests.unit.referee.referee_helpers import make_config

Script = Callable[[KinematicWorld], None]


def play(config: RefereeConfig, script: dict[int, Script] | None = None) -> Referee:
    world = KinematicWorld(
        {RobotId(c, n): (0.0, 0.0, 0.0) for c in TeamColor for n in (1, 2, 3, 4)}
    )
    clock = FakeClock()
    referee = Referee(config=config, clock=clock)
    script = dict(script or {})
    limit_ms = 2_000_000
    while not referee.finished and world.sim_time_ms < limit_ms:
        for command in referee.step(world.snapshot()):
            world.apply(command)
        action = script.pop(world.sim_time_ms, None)
        if action is not None:
            action(world)
        world.step()
        clock.advance(world.step_ms / 1000.0)  # real time factor 1
    return referee


def league_config() -> RefereeConfig:
    return make_config(players=4, timing=TimingConfig())  # 600 s halves, 120 s / 15 s waits


@pytest.mark.slow
def test_still_robots_play_two_halves_to_a_goalless_draw() -> None:
    referee = play(league_config())
    result = referee.result()
    assert referee.finished and result["winner"] == "draw"
    assert result["score"] == {"red": 0, "blue": 0}
    summary = result["events_summary"]
    assert isinstance(summary, dict) and summary["dropped_ball"] >= 6
    halves = [e for e in referee.events if e.type == "state" and e.reason == "FINISHED"]
    assert [e.details["half"] for e in halves] == [1, 2]
    # 120 s wait + READY 45 s and SET 5 s before each half's kick-off (the clock stands still,
    # league GameController getRemainingGameTime) + 600 s + 15 s break + 50 s + 600 s
    assert halves[-1].sim_time_ms == pytest.approx(1_435_000, abs=100)


def _place(x: float, y: float) -> Script:
    def action(world: KinematicWorld) -> None:
        world.ball, world.ball_velocity = (x, y, 0.07), (0.0, 0.0, 0.0)

    return action


def _kick(kicker: RobotId, vx: float) -> Script:
    def action(world: KinematicWorld) -> None:
        world.ball_velocity = (vx, 0.0, 0.0)
        world.touch(kicker)

    return action


def _shot(at_ms: int, x: float, y: float, vx: float, kicker: RobotId) -> dict[int, Script]:
    """The ball out of the centre circle at (x, y), then kicked by ``kicker`` a step later (a
    goal counts after a kick-off once a robot touched the ball out of the circle)."""
    return {at_ms - 8: _place(x, y), at_ms: _kick(kicker, vx)}


@pytest.mark.slow
def test_scripted_ball_gives_the_expected_score() -> None:
    # Each shot in PLAYING (after a goal, READY 45 s and SET 5 s; a ball still for 120 s is
    # dropped, READY and SET again): the referee puts the ball on the centre spot when SET
    # begins, so a ball rolled in READY scores nothing.
    red, blue = RobotId(TeamColor.RED, 2), RobotId(TeamColor.BLUE, 2)
    script = {
        **_shot(200_000, 3.8, 0.3, 2.0, red),  # first half: red plays left, scores on the right
        **_shot(300_000, -3.8, -0.5, -2.0, blue),  # blue scores on the left
        **_shot(400_000, 3.8, 1.0, 2.0, red),  # red again
        **_shot(900_000, 3.8, 0.0, 2.0, blue),  # second half: blue plays left now, scores right
        **_shot(1_200_000, 2.0, 2.8, 0.0, red),  # not a goal
    }
    referee = play(league_config(), script)
    result = referee.result()
    assert result["score"] == {"red": 2, "blue": 2}
    assert result["winner"] == "draw"
    goals = [(e.sim_time_ms // 1000, e.team.value) for e in referee.events if e.type == "goal"]  # type: ignore[union-attr]
    assert [team for _, team in goals] == ["red", "blue", "red", "blue"]
