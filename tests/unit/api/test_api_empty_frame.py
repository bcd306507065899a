"""An empty ``ActuatorRequests`` (a 0-length frame) over a real socket pair."""

from __future__ import annotations

import socket
import struct
import time

import pytest

from contracts.robot_api import messages_pb2 as pb
from simulator.api.connection import RECV_CHUNK, ClientClosed, Connection
from simulator.api.framing import encode_frame
from simulator.api.stats import RobotStats


def test_an_empty_request_is_skipped_and_the_client_stays_connected() -> None:
    """League ``controllers/player/player.cpp``: the player skips a 0-length message instead of
    dropping the client; here it also answers the measurement (lockstep waits no longer)."""
    ours, theirs = socket.socketpair()
    ours.setblocking(False)
    try:
        conn = Connection(sock=ours, peer="test", key="red 1", stats=RobotStats(),
                          queue_limit=1000, time_bank_s=1.0)
        conn.answered = False
        request = pb.ActuatorRequests()
        request.motor_positions.add(name="HeadYaw", position=0.5)
        theirs.sendall(struct.pack(">I", 0) + encode_frame(request.SerializeToString())
                       + struct.pack(">I", 0))
        time.sleep(0.05)
        assert conn.read(time.monotonic()) == 3
        assert conn.answered and conn.stats.bad_frames == 0 and not conn.closed
        [taken] = conn.take_requests()  # the empty ones add nothing to apply
        assert isinstance(taken, pb.ActuatorRequests)
        assert [(m.name, m.position) for m in taken.motor_positions] == [("HeadYaw", 0.5)]
    finally:
        ours.close()
        theirs.close()


def _frame_of(size: int) -> bytes:
    """A framed ActuatorRequests of exactly ``size`` bytes, header included."""
    for length in range(size, 0, -1):
        request = pb.ActuatorRequests()
        request.motor_positions.add(name="x" * length, position=0.25)
        frame = encode_frame(request.SerializeToString())
        if len(frame) == size:
            return frame
    raise AssertionError(size)


def test_requests_read_together_with_the_close_are_counted() -> None:
    """A client that sends a full receive's worth of requests and closes: the server's read
    takes them and meets the end of the stream in the same call, raises ClientClosed, and
    counts what it took all the same."""
    ours, theirs = socket.socketpair()
    ours.setblocking(False)
    try:
        conn = Connection(sock=ours, peer="test", key="blue 1", stats=RobotStats(),
                          queue_limit=1000, time_bank_s=1.0)
        theirs.sendall(_frame_of(RECV_CHUNK // 2) * 2)  # one receive exactly, then the end
        theirs.close()
        time.sleep(0.05)
        with pytest.raises(ClientClosed, match="client disconnected"):
            conn.read(time.monotonic())
        assert conn.stats.messages_in == 2 and conn.stats.bytes_in == RECV_CHUNK
    finally:
        ours.close()
