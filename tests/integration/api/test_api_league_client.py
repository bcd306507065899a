"""A client written like the league's own (``testkit.league_client``: the length and the body of
each request in two writes, no ``TCP_NODELAY``), over real sockets: lockstep runs at full speed
with it, and the server's round-trip statistics are the wait the client causes."""

from __future__ import annotations

import statistics
import time
from typing import Any

import pytest

from simulator.api import FakeDeviceWorld, LockstepSettings
from testkit.league_client import LeagueStyleClient, neck_request
from tests.integration.api.harness import RED1, running_server, wait_until

LOCKSTEP = LockstepSettings(deadline_s=0.05, time_bank_s=1.0)


@pytest.mark.parametrize("send_thread", [False, True], ids=["step-thread-io", "io-thread"])
def test_lockstep_with_a_league_style_client_is_not_held_by_delayed_acks(
    send_thread: bool,
) -> None:
    """Each request's body waits for the ACK of its length (Nagle); a server that delays that
    ACK (40 ms on Linux) holds every step 40 ms: at most 25 requests per second."""
    exchanges = 200
    with running_server(robots=(RED1,), lockstep=LOCKSTEP, world=FakeDeviceWorld((RED1,)),
                        pause_s=0.0, send_thread=send_thread) as (driver, ports):  # fmt: skip
        with LeagueStyleClient("127.0.0.1", ports[RED1]) as client:
            client.send(neck_request(0.0, enable=True))
            for _ in range(20):  # connected, sensors on, the server's first steps done
                client.exchange(neck_request(0.1))
            started = time.monotonic()
            for k in range(exchanges):
                client.exchange(neck_request(0.001 * k))
            rate = exchanges / (time.monotonic() - started)
        stats = driver.server.statistics()["red-1"]
    assert stats["slow_periods"] == 0 and stats["decode_errors"] == 0
    assert rate >= 150, f"{rate:.0f} requests/s"


@pytest.mark.parametrize("split_writes", [True, False], ids=["two-writes", "one-write"])
@pytest.mark.parametrize("send_thread", [False, True], ids=["step-thread-io", "io-thread"])
def test_server_round_trip_is_the_wait_the_client_causes(
    send_thread: bool, split_writes: bool
) -> None:
    """The client takes 5 ms to answer each measurement: the server's round trip (measurement
    sent to answer received) is those 5 ms and the loopback's transit, not the time between
    the start of the server's wait and the start of its last ``select`` (which read 0.1 ms)."""
    think_s = 0.005
    with running_server(robots=(RED1,), lockstep=LOCKSTEP, world=FakeDeviceWorld((RED1,)),
                        pause_s=0.0, send_thread=send_thread) as (driver, ports):  # fmt: skip
        with LeagueStyleClient("127.0.0.1", ports[RED1], split_writes=split_writes) as client:
            client.send(neck_request(0.0, enable=True))
            wait_until(lambda: driver.server.connected())
            for k in range(60):
                client.exchange(neck_request(0.001 * k), think=lambda: time.sleep(think_s))
        stats = driver.server.statistics()["red-1"]
    client_ms = statistics.median(client.answer_s) * 1000.0
    server_ms = stats["round_trip_ms"]["p50"]
    assert client_ms >= think_s * 1000.0
    assert server_ms == pytest.approx(client_ms, rel=0.2), (server_ms, client_ms)


class _SlowStep:
    """A world whose step takes ``step_s`` of wall time (the server's part of the cycle)."""

    def __init__(self, world: Any, step_s: float) -> None:
        self._world, self._step_s = world, step_s

    def __getattr__(self, name: str) -> Any:
        return getattr(self._world, name)

    def step(self) -> None:
        time.sleep(self._step_s)
        self._world.step()


@pytest.mark.parametrize("split_writes", [True, False], ids=["two-writes", "one-write"])
@pytest.mark.parametrize("send_thread", [False, True], ids=["step-thread-io", "io-thread"])
def test_server_reply_is_the_wait_the_client_has(send_thread: bool, split_writes: bool) -> None:
    """The server's step takes 10 ms: the client's own wait (answer written to the next
    measurement, what the league's client waits for in ``receive``) is those 10 ms and the
    transits, and the server's ``reply_ms`` (the answer's first byte received to the next
    measurement written) says the same within 20 %."""
    step_s = 0.010
    world = _SlowStep(FakeDeviceWorld((RED1,)), step_s)
    with running_server(robots=(RED1,), lockstep=LOCKSTEP, world=world, pause_s=0.0,
                        send_thread=send_thread) as (driver, ports):
        with LeagueStyleClient("127.0.0.1", ports[RED1], split_writes=split_writes) as client:
            client.send(neck_request(0.0, enable=True))
            wait_until(lambda: driver.server.connected())
            for k in range(60):
                client.exchange(neck_request(0.001 * k))
        stats = driver.server.statistics()["red-1"]
    client_ms = statistics.median(client.round_trip_s) * 1000.0
    server_ms = stats["reply_ms"]["p50"]
    assert client_ms >= step_s * 1000.0
    assert stats["reply_samples"] >= 50
    assert server_ms == pytest.approx(client_ms, rel=0.2), (server_ms, client_ms)
