"""The server's round trip (``round_trip_ms``) starts when a measurement's last byte is written
to the client's socket, not when the step queued it: the time the measurement waited in the
queue for the I/O thread (or its frame to be built) is the server's, not a wait the client
caused."""

from __future__ import annotations

import socket
import time
from collections.abc import Iterator

import pytest

from contracts.robot_api import messages_pb2 as pb
from simulator.api.connection import Connection
from simulator.api.framing import encode_frame

from .conftest import connection_pair, read_sent


@pytest.fixture(params=[False, True], ids=["step-thread-io", "io-thread"])
def pair(request: pytest.FixtureRequest) -> Iterator[tuple[Connection, socket.socket]]:
    with connection_pair(threaded=request.param) as both:
        yield both


def _answer(conn: Connection, theirs: socket.socket) -> None:
    request = pb.ActuatorRequests()
    request.motor_positions.add(name="HeadYaw", position=0.1)
    read_sent(conn, theirs, encode_frame(request.SerializeToString()))


def test_the_round_trip_starts_when_the_measurement_is_written(
    pair: tuple[Connection, socket.socket],
) -> None:
    conn, theirs = pair
    queued_at = time.monotonic() - 5.0  # queued long before it is written
    conn.send(encode_frame(b"\x08\x01"), queued_at)
    if conn.threaded:  # the I/O thread writes it
        assert conn.last_sent_at == queued_at
        assert conn.write_queued()
    written = conn.last_sent_at
    assert written is not None and written > queued_at + 4.0
    _answer(conn, theirs)
    (round_trip,) = conn.stats.round_trip_s
    assert 0.0 <= round_trip < 4.0, round_trip  # not the 5 s the frame waited in the queue


def test_the_clients_wait_seen_here_starts_at_its_requests_first_byte(
    pair: tuple[Connection, socket.socket],
) -> None:
    """``reply_ms``: a request written as the league's client writes it, its length first and
    its body later (here 0.2 s later, as a held segment would arrive), then the measurement
    after it: the server's figure spans from the length's arrival to the measurement written,
    the wait the client has, not only from the body's arrival."""
    conn, theirs = pair
    request = pb.ActuatorRequests()
    request.motor_positions.add(name="HeadYaw", position=0.1)
    frame = encode_frame(request.SerializeToString())
    theirs.sendall(frame[:4])
    time.sleep(0.02)
    first = time.monotonic()
    assert conn.read(first) == 0  # the length only: no request yet
    time.sleep(0.2)
    theirs.sendall(frame[4:])
    for _ in range(200):
        if conn.read(time.monotonic()):
            break
        time.sleep(0.005)
    else:
        raise AssertionError("the request's body did not arrive")
    assert conn.stats.reply_s.tolist() == []  # no measurement written after it yet
    conn.send(encode_frame(b"\x08\x01"), time.monotonic())
    if conn.threaded:
        assert conn.write_queued()
    written = conn.last_sent_at
    assert written is not None
    (reply,) = conn.stats.reply_s
    assert reply == pytest.approx(written - first, abs=1e-9)
    assert reply >= 0.2
    # the next measurement, with no request since, adds nothing
    conn.send(encode_frame(b"\x08\x02"), time.monotonic())
    if conn.threaded:
        assert conn.write_queued()
    assert len(conn.stats.reply_s) == 1
    assert conn.stats.to_dict()["reply_samples"] == 1
