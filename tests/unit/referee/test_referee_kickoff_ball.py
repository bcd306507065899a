"""SET begins: the ball is put on the centre spot, as the league's referee places it for the
kick-off, wherever a robot pushed it in READY."""

from __future__ import annotations

import logging

import pytest

from contracts.field import KID_FIELD
from referee import FakeClock, Referee
from referee.gamecontroller import GameState
from referee.snapshot import PlaceBall
from tests.unit.referee.referee_helpers import BLUE, RED, make_config, robot, snapshot


def test_a_ball_pushed_in_ready_is_on_the_centre_spot_at_set(
    caplog: pytest.LogCaptureFixture,
) -> None:
    caplog.set_level(logging.INFO, logger="referee")
    clock = FakeClock()
    ref = Referee(config=make_config(side_left=RED), clock=clock)
    robots = (robot(RED, 1, -2.0, 0.0), robot(BLUE, 1, 2.0, 0.0))
    pushed = (-0.72, -0.62, KID_FIELD.ball_radius_m)  # a striker walked into it in READY
    ms, at_set = 0, None
    while ref.gc.state is not GameState.SET:
        ready = ref.gc.state is GameState.READY
        commands = list(ref.step(snapshot(ms, robots, ball=pushed if ready else (0.0, 0.0, 0.07))))
        clock.advance(0.008)
        ms += 8
        at_set = commands
        assert ms < 200_000, "no SET"
    assert at_set is not None
    assert PlaceBall(position=(0.0, 0.0, KID_FIELD.ball_radius_m)) in at_set
    assert "Ball moved in READY to (-0.72, -0.62); placed on the centre spot." in caplog.text
