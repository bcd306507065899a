"""The budget of one robot API client's requests (:mod:`simulator.api.bounds`): bytes and frames
charged in the reader before anything else is done with them, refilled by real time and by the
measurements sent; a client over it is not read and is marked slow; the size limit."""

from __future__ import annotations

import socket
from collections.abc import Iterator
from contextlib import contextmanager

from contracts.robot_api import messages_pb2 as pb
from simulator.api.bounds import BYTE_COST, ReadBudget
from simulator.api.connection import Connection
from simulator.api.fastreq import Notice
from simulator.api.framing import FrameDecoder, encode_frame
from simulator.api.stats import RobotStats

from .conftest import connection_pair


@contextmanager
def _connection(budget: ReadBudget) -> Iterator[tuple[Connection, socket.socket, RobotStats]]:
    stats = RobotStats()
    with connection_pair(key="red-1", queue_limit=4, stats=stats) as (conn, theirs):
        conn.budget = budget
        yield conn, theirs, stats


def _small() -> bytes:
    request = pb.ActuatorRequests()
    request.motor_positions.add(name="Neck", position=0.5)
    return encode_frame(request.SerializeToString())


def test_budget_refills_with_time_and_measurements_up_to_its_burst() -> None:
    budget = ReadBudget(0.0, rate=100, burst=10, per_measurement=2)
    assert budget.refill(0.0, 0) == 10
    budget.level = 0.0
    assert budget.refill(0.05, 0) == 5  # 50 ms of 100 a second
    assert budget.refill(0.05, 2) == 9  # two measurements sent since
    assert budget.refill(10.0, 100) == 10  # never more than the burst


def test_decoder_cuts_no_more_frames_than_asked_and_keeps_the_rest() -> None:
    decoder = FrameDecoder()
    frames = decoder.feed(_small() * 5, 2)
    assert len(frames) == 2 and decoder.held
    assert len(decoder.feed(b"", 2)) == 2 and decoder.held
    assert len(decoder.feed(b"", 2)) == 1 and not decoder.held


def test_a_connection_takes_what_its_budget_pays_for_then_pauses_and_is_marked_slow() -> None:
    frame = _small()
    with _connection(ReadBudget(0.0, rate=100, burst=10, per_measurement=2)) as (
        conn, theirs, stats,
    ):  # fmt: skip
        theirs.sendall(frame * 50)
        # 10 units: the bytes received (50 frames) cost a fraction, each frame one
        bytes_cost = len(frame) * 50 * BYTE_COST
        assert conn.read(0.0) == int(10 - bytes_cost)
        assert conn.paused and conn.slow and stats.slow_periods == 1
        assert len(conn.take_requests()) == int(10 - bytes_cost)
        assert not conn.resume(0.001)  # 0.1 unit refilled: not enough for a frame
        conn.measurements = 2  # two measurements sent: 4 units
        assert conn.resume(0.001) and not conn.paused
        assert conn.read(0.001) == 4  # from the frames kept buffered, nothing received
        assert conn.paused and stats.slow_periods == 1  # still slow: one period
        assert stats.bytes_in == len(frame) * 50 and stats.messages_in == 13


def test_an_honest_lockstep_client_never_meets_its_budget() -> None:
    frame = _small()
    with _connection(ReadBudget(0.0)) as (conn, theirs, stats):
        for step in range(5000):  # one answer per measurement, a world 100 times real time
            conn.measurements += 1
            theirs.sendall(frame)
            assert conn.read(step * 0.00008) == 1
        assert not conn.paused and not conn.slow and stats.slow_periods == 0


def test_a_request_over_the_size_limit_is_dropped_counted_and_told() -> None:
    with _connection(ReadBudget(0.0)) as (conn, theirs, stats):
        conn.max_request_bytes = 200
        large = pb.ActuatorRequests()
        large.motor_positions.add(name="x" * 500, position=0.5)
        theirs.sendall(encode_frame(large.SerializeToString()) + _small())
        assert conn.read(0.0) == 1 and conn.answered
        notice, request = conn.take_requests()
        assert isinstance(notice, Notice) and notice.text == (
            f"ActuatorRequests of {large.ByteSize()} bytes is above the limit of 200 bytes,"
            " ignored."
        )
        assert isinstance(request, pb.ActuatorRequests)  # the small one, decoded
        assert stats.dropped_in == {"size": 1}
        assert stats.dropped_in_bytes == large.ByteSize()
        assert not conn.closed
