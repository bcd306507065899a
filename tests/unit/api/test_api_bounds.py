"""The bounds on one robot API client's requests: size, bytes and messages per second."""

from __future__ import annotations

import socket

from contracts.robot_api import messages_pb2 as pb
from simulator.api.bounds import RequestBounds, TokenBucket
from simulator.api.connection import Connection
from simulator.api.fastreq import Notice
from simulator.api.framing import encode_frame
from simulator.api.stats import RobotStats


def test_token_bucket_spends_its_burst_then_refills_at_its_rate() -> None:
    bucket = TokenBucket(rate=100, burst=10, now=0.0)
    assert all(bucket.take(1, 0.0) for _ in range(10))
    assert not bucket.take(1, 0.0)
    assert bucket.take(5, 0.05) and not bucket.take(1, 0.05)
    assert bucket.take(10, 10.0) and not bucket.take(1, 10.0)  # never more than the burst


def test_bounds_drop_oversized_and_over_rate_requests_with_the_reason() -> None:
    bounds = RequestBounds(0.0, max_bytes=1000, rate_bytes_s=10, burst_bytes=2000,
                           rate_messages_s=100, burst_messages=5)
    assert bounds.admit(1001, 0.0) == "size"
    assert [bounds.admit(100, 0.0) for _ in range(6)] == [None] * 5 + ["rate"]
    assert bounds.admit(100, 1.0) is None
    assert [bounds.admit(1000, 2.0) for _ in range(2)] == [None, "rate"]  # the bytes


def test_a_connection_drops_and_counts_what_is_over_its_bounds() -> None:
    ours, theirs = socket.socketpair()
    ours.setblocking(False)
    stats = RobotStats()
    conn = Connection(sock=ours, peer="test", key="red-1", stats=stats, queue_limit=4,
                      time_bank_s=1.0)
    conn.bounds = RequestBounds(0.0, max_bytes=200, rate_messages_s=0.001, burst_messages=3)
    small = pb.ActuatorRequests()
    small.motor_positions.add(name="Neck", position=0.5)
    large = pb.ActuatorRequests()
    large.motor_positions.add(name="x" * 500, position=0.5)
    theirs.sendall(encode_frame(large.SerializeToString())
                   + encode_frame(small.SerializeToString()) * 5)
    assert conn.read(0.0) == 3
    notice, *requests = conn.take_requests()  # the oversize one is told, not decoded
    assert isinstance(notice, Notice) and notice.text == (
        f"ActuatorRequests of {large.ByteSize()} bytes is above the limit of 200 bytes, ignored."
    )
    assert len(requests) == 3
    assert stats.dropped_in == {"size": 1, "rate": 2}
    assert stats.to_dict()["dropped_in"] == {"size": 1, "rate": 2}
    assert stats.dropped_in_bytes == large.ByteSize() + 2 * small.ByteSize()
    assert not conn.closed
    ours.close()
    theirs.close()
