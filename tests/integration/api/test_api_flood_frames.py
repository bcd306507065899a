"""A robot flooding its port with small valid requests, over real sockets and the real world:
its requests cost the step no more than its budget (read no faster than it allows, the rest
left in the kernel), it is marked slow as a robot too slow for lockstep is, and the other
team's robot keeps its lockstep pace."""

from __future__ import annotations

import threading
import time

import pytest

from simulator.api import LockstepSettings
from testkit.flood_client import flood
from testkit.league_client import LeagueStyleClient, neck_request
from tests.integration.api.harness import BLUE1, RED1, running_server, wait_until

STEPS = 250


def _answer(client: LeagueStyleClient, steps: int) -> float:
    """Seconds the honest client takes to answer ``steps`` measurements, one step each."""
    started = time.monotonic()
    for k in range(steps):
        client.exchange(neck_request(0.001 * k))
    return time.monotonic() - started


@pytest.mark.parametrize("send_thread", [False, True], ids=["step-thread-io", "io-thread"])
def test_a_robot_flooding_small_valid_requests_costs_only_itself(send_thread: bool) -> None:
    lockstep = LockstepSettings(deadline_s=0.05, time_bank_s=0.2)
    with running_server(robots=(RED1, BLUE1), lockstep=lockstep, pause_s=0.0, hold=True,
                        send_thread=send_thread) as (driver, ports):  # fmt: skip
        with LeagueStyleClient("127.0.0.1", ports[BLUE1], split_writes=False) as honest:
            honest.send(neck_request(0.0, enable=True))
            wait_until(lambda: driver.server.connected())
            driver.max_steps = None
            _answer(honest, 50)  # warm
            alone_s = _answer(honest, STEPS)
            stop, sent = threading.Event(), [0]
            flooder = threading.Thread(target=flood, args=(ports[RED1], stop, sent))
            flooder.start()
            try:
                deadline = time.monotonic() + 20
                while driver.server.statistics()["red-1"]["messages_in"] < 500:
                    assert time.monotonic() < deadline, "the flood did not start"
                    _answer(honest, 1)  # the honest robot plays on meanwhile
                red_before = driver.server.statistics()["red-1"]["messages_in"]
                flooded_s = _answer(honest, STEPS)
                # read while it floods: its own close afterwards (unread measurements, so a
                # reset) may fail the server's next send to it, which is no drop for flooding
                stats = driver.server.statistics()
                red_during = stats["red-1"]["messages_in"] - red_before
            finally:
                stop.set()
                flooder.join(timeout=10)
    red, blue = stats["red-1"], stats["blue-1"]
    assert sent[0] > red["messages_in"]  # it wrote more than the server took
    assert red["slow_periods"] >= 1  # marked as a robot too slow for lockstep is
    assert red["decode_errors"] == 0 and red["disconnects"] == []
    # what it got decoded while the honest robot played STEPS steps: its budget, a few per step
    assert red_during < 20 * STEPS, red_during
    assert blue["slow_periods"] == 0 and blue["dropped_in"] == {}
    # the honest robot's pace with the flood beside it
    assert flooded_s < 2 * alone_s + 0.5, (alone_s, flooded_s)  # without the budget: 31 times
