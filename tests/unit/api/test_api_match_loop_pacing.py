"""Async pacing holds ``maximum_real_time_factor`` even when socket events end each poll early."""

from __future__ import annotations

import time
from types import SimpleNamespace

import numpy as np

from referee.snapshot import RefereeEvent, WorldCommand, WorldSnapshot
from simulator.api import LockstepSettings
from simulator.match_loop import LoopSettings, MatchLoop
from simulator.telemetry import NullTelemetry


class _World:
    step_ms = 8

    def __init__(self) -> None:
        self.sim_time_ms = 0
        self.data = SimpleNamespace(xpos=np.zeros((2, 3)), xquat=np.zeros((2, 4)))

    def step(self) -> None:
        self.sim_time_ms += self.step_ms

    def snapshot(self) -> WorldSnapshot:
        return None  # type: ignore[return-value]  # the fake referee never looks at it

    def apply(self, command: WorldCommand) -> None:
        raise AssertionError("no commands expected")


class _Referee:
    waiting_for_wall_clock = False
    game_state: dict[str, object] = {}

    def __init__(self, world: _World, end_ms: int) -> None:
        self.events: list[RefereeEvent] = []
        self._world = world
        self._end_ms = end_ms

    @property
    def finished(self) -> bool:
        return self._world.sim_time_ms >= self._end_ms

    def step(self, snapshot: WorldSnapshot) -> list[WorldCommand]:
        return []


class _BusyServer:
    """Every poll returns at once, as when a client's request arrives."""

    stop_requested = False
    connection_changes = 0

    def __init__(self) -> None:
        self.polls = 0

    def poll(self, timeout_s: float = 0.0) -> None:
        self.polls += 1

    def apply_requests(self, step_time_ms: int) -> None:
        return None

    def publish(self, time_ms: int) -> None:
        return None

    def connected(self) -> list[str]:
        return []


def test_pacing_waits_until_due_although_polls_return_early() -> None:
    world, server = _World(), _BusyServer()
    loop = MatchLoop(
        world=world,
        referee=_Referee(world, end_ms=200),
        server=server,  # type: ignore[arg-type]
        recorder=None,
        telemetry=NullTelemetry(),
        settings=LoopSettings(
            stepping="async",
            maximum_real_time_factor=2.0,
            lockstep=LockstepSettings(deadline_s=0.05, time_bank_s=1.0),
            end_of_game_real_s=0.0,
            max_duration_real_s=10.0,
        ),
    )
    started = time.monotonic()
    assert loop.run() == "finished"
    elapsed = time.monotonic() - started
    assert world.sim_time_ms == 200
    assert elapsed >= 0.2 / 2.0 - 0.01  # 200 ms of simulated time at most twice as fast
    assert server.polls > 25  # it did wait (busily here, with this server)
