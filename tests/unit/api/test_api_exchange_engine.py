"""The compiled exchange (``simulator/api/native/exchange.c``) alone, over a pair of connected
sockets: what it takes onto the board and what it hands back, with the bytes received."""

from __future__ import annotations

import math
import socket
import struct
import threading
import time
from collections.abc import Iterator

import numpy as np
import pytest

from contracts.robot_api import messages_pb2 as pb
from simulator.api import exchange as ex
from simulator.api.fastreq import scan_positions

NAMES = ("Neck", "Head", "AnkleL")
MEASUREMENT = struct.pack(">I", 5) + b"hello"


def _body(values: tuple[float, ...], names: tuple[str, ...] = NAMES) -> bytes:
    request = pb.ActuatorRequests()
    for name, value in zip(names, values, strict=False):  # (fewer values: a shorter body)
        request.motor_positions.add(name=name, position=value)
    body: bytes = request.SerializeToString()
    return body


def _frame(body: bytes) -> bytes:
    return struct.pack(">I", len(body)) + body


class _Pair:
    """An engine with one robot: the server's socket ``server`` and the client's ``client``;
    the robot's board span ``targets``."""

    def __init__(self, engine: ex.Exchange) -> None:
        self.engine = engine
        self.server, self.client = socket.socketpair()
        self.server.setblocking(False)
        template = scan_positions(_body((0.1, 0.2, 0.3)))
        assert template is not None
        body, offsets = ex.template_layout(template)
        self.targets = np.zeros(len(NAMES))
        self._keep = (body, offsets)
        assert engine._lib.ex_robot(engine._handle, 0, self.server.fileno(), body, len(body),
                                    offsets.ctypes.data, len(offsets),
                                    self.targets.ctypes.data) == 0  # fmt: skip
        self._frames = np.frombuffer(MEASUREMENT, dtype=np.uint8)
        self._spans = np.asarray([0, len(MEASUREMENT)], dtype=np.int64)

    def go(self, frame: bytes | None = None) -> None:
        if frame is not None:
            self._frames = np.frombuffer(frame, dtype=np.uint8)
            self._spans = np.asarray([0, len(frame)], dtype=np.int64)
        self.engine._lib.ex_go(self.engine._handle, 1, self._frames.ctypes.data,
                               self._spans.ctypes.data)  # fmt: skip

    def wait(self, wait_s: float = 2.0) -> tuple[int, bytes]:
        """The robot's status and the bytes handed back."""
        self.engine._lib.ex_wait(self.engine._handle, wait_s)
        return int(self.engine.results["status"][0]), self.engine.received(0)

    def close(self) -> None:
        self.engine._lib.ex_clear(self.engine._handle)
        self.server.close()
        self.client.close()


@pytest.fixture
def pair() -> Iterator[_Pair]:
    engine = ex.Exchange.start(None)
    if engine is None:
        pytest.skip("no C compiler here: the exchange is not built")
    robot = _Pair(engine)
    try:
        yield robot
    finally:
        robot.close()
        engine.close()


def _answer(pair: _Pair, data: bytes) -> None:
    assert pair.client.recv(len(MEASUREMENT), socket.MSG_WAITALL) == MEASUREMENT
    pair.client.sendall(data)


def test_the_usual_answer_is_taken_onto_the_board(pair: _Pair) -> None:
    for step in range(3):
        values = (0.5 + step, -0.25, 1e-3)
        pair.go()
        _answer(pair, _frame(_body(values)))
        assert pair.wait() == (ex.TAKEN, b"")
        assert pair.targets.tolist() == list(values)
        assert pair.engine.results["sent"][0] == len(MEASUREMENT)
        assert pair.engine.results["received"][0] == len(_frame(_body(values)))


@pytest.mark.parametrize(
    "answer",
    [
        _frame(_body((0.1, math.nan, 0.3))),  # a target that is not a number
        _frame(_body((0.1, 0.2, 0.3))) * 2,  # two requests at once
        _frame(_body((0.1, 0.2, 0.3), ("Neck", "Head", "AnkleR"))),  # another name, same size
        _frame(b""),  # an empty request
        _frame(_body((0.1, 0.2))),  # fewer targets
    ],
    ids=["nan", "two", "other-names", "empty", "shorter"],
)
def test_anything_else_is_handed_back_with_its_bytes(pair: _Pair, answer: bytes) -> None:
    pair.go()
    _answer(pair, answer)
    status, data = pair.wait()
    assert (status, data) == (ex.HANDED, answer)
    assert pair.targets.tolist() == [0.0, 0.0, 0.0]  # the board is untouched


def test_a_frame_in_two_writes_is_taken_whole(pair: _Pair) -> None:
    answer = _frame(_body((0.1, 0.2, 0.3)))

    def client() -> None:
        _answer(pair, answer[:4])
        time.sleep(0.01)
        pair.client.sendall(answer[4:])

    writer = threading.Thread(target=client)
    writer.start()
    pair.go()
    assert pair.wait() == (ex.TAKEN, b"")
    writer.join()
    assert pair.targets.tolist() == [0.1, 0.2, 0.3]


def test_a_frame_still_open_at_the_deadline_is_handed_back(pair: _Pair) -> None:
    answer = _frame(_body((0.1, 0.2, 0.3)))
    pair.go()
    _answer(pair, answer[:7])
    started = time.monotonic()
    assert pair.wait(0.05) == (ex.PENDING, answer[:7])
    assert time.monotonic() - started < 1.5


def test_nothing_at_the_deadline_is_pending_with_no_bytes(pair: _Pair) -> None:
    pair.go()
    assert pair.client.recv(len(MEASUREMENT), socket.MSG_WAITALL) == MEASUREMENT
    assert pair.wait(0.02) == (ex.PENDING, b"")


def test_the_end_of_the_stream_is_handed_back(pair: _Pair) -> None:
    pair.go()
    assert pair.client.recv(len(MEASUREMENT), socket.MSG_WAITALL) == MEASUREMENT
    pair.client.shutdown(socket.SHUT_WR)
    assert pair.wait() == (ex.HANDED, b"")


def test_a_measurement_the_socket_does_not_take_whole_is_a_short_send(pair: _Pair) -> None:
    big = struct.pack(">I", 1 << 23) + bytes(1 << 23)
    pair.go(big)
    status, _ = pair.wait()
    sent = int(pair.engine.results["sent"][0])
    assert status == ex.SEND_SHORT
    assert 0 <= sent < len(big)


def test_a_failed_send_is_reported_with_its_error(pair: _Pair) -> None:
    pair.client.close()
    pair.go()
    status, _ = pair.wait()
    assert status == ex.SEND_ERROR
    assert pair.engine.results["error"][0] > 0


def test_a_robot_given_a_bad_layout_is_refused() -> None:
    engine = ex.Exchange.start(None)
    if engine is None:
        pytest.skip("no C compiler here: the exchange is not built")
    try:
        targets = np.zeros(2)
        offsets = np.asarray([4, 2], dtype=np.int32)  # overlapping targets
        assert engine._lib.ex_robot(engine._handle, 0, 0, bytes(20), 20, offsets.ctypes.data, 2,
                                    targets.ctypes.data) == -1  # fmt: skip
        offsets = np.asarray([16], dtype=np.int32)  # past the body's end
        assert engine._lib.ex_robot(engine._handle, 0, 0, bytes(20), 20, offsets.ctypes.data, 1,
                                    targets.ctypes.data) == -1  # fmt: skip
        assert engine._lib.ex_robot(engine._handle, ex.MAX_ROBOTS, 0, bytes(20), 20,
                                    offsets.ctypes.data, 0, targets.ctypes.data) == -1  # fmt: skip
    finally:
        engine.close()
