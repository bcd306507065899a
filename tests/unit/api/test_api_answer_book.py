"""Lockstep's answer book: who owes an answer is kept as it changes, so that the usual wait
looks at no robot one by one, whatever their number."""

from __future__ import annotations

import socket
import time
from collections.abc import Iterator

import pytest

from contracts.robot_api import messages_pb2 as pb
from simulator.api import LockstepSettings, wait_lockstep
from simulator.api.connection import AnswerBook, Connection
from simulator.api.framing import encode_frame

from .conftest import connection_pair

# a deadline no answer here comes near, however loaded the machine (the test times nothing)
SETTINGS = LockstepSettings(deadline_s=60.0, time_bank_s=1.0)


@pytest.fixture
def pair() -> Iterator[tuple[Connection, socket.socket, AnswerBook]]:
    book = AnswerBook()
    with connection_pair() as (conn, theirs):
        conn.book = book
        yield conn, theirs, book


def _answer(conn: Connection, theirs: socket.socket) -> None:
    request = pb.ActuatorRequests()
    request.motor_positions.add(name="HeadYaw", position=0.1)
    theirs.sendall(encode_frame(request.SerializeToString()))
    for _ in range(100):
        if conn.read(time.monotonic()):
            return
        time.sleep(0.005)
    raise AssertionError("the request did not arrive")


def test_a_connection_keeps_its_place_in_the_book(
    pair: tuple[Connection, socket.socket, AnswerBook],
) -> None:
    conn, theirs, book = pair
    conn.send(b"\0\0\0\0", time.monotonic())  # a measurement: its answer is owed
    assert book.owing == {conn} and not book.slow
    _answer(conn, theirs)
    assert not book.owing and conn.answered
    conn.send(b"\0\0\0\0", time.monotonic())
    conn.mark_slow(True)  # out of time: lockstep goes on without it
    assert not book.owing and book.slow == {conn}
    conn.send(b"\0\0\0\0", time.monotonic())  # a slow client owes nothing lockstep waits for
    assert not book.owing
    conn.mark_slow(False)  # waited for again, still owing its answer
    assert book.owing == {conn} and not book.slow
    book.forget(conn)  # dropped
    assert not book.owing and not book.slow


class _Slots(dict[object, object]):
    """The server's robots, counting how often the wait goes through them one by one."""

    looked = 0

    def values(self):  # type: ignore[no-untyped-def]
        _Slots.looked += 1
        return super().values()


class _Client:
    answered = False
    slow = False
    closed = False


class _Server:
    stop_requested = False
    awaiting_answers = False
    exchanging = False  # no exchange thread (simulator.api.exchange)

    def settle_exchange(self, wait_s: float) -> bool:
        return False

    def __init__(self, book: AnswerBook, answers: list[_Client]) -> None:
        self.answers = book
        self.slots = _Slots()
        self._arriving = answers
        self.polls = 0

    def poll(self, timeout_s: float = 0.0) -> None:
        """Each poll, one more client's answer arrives."""
        assert self.awaiting_answers
        self.polls += 1
        if self._arriving:
            conn = self._arriving.pop()
            conn.answered = True
            self.answers.owing.discard(conn)


def test_the_usual_wait_looks_at_no_robot_one_by_one() -> None:
    book = AnswerBook()
    conns = [_Client() for _ in range(8)]
    book.owing.update(conns)  # type: ignore[arg-type]
    server = _Server(book, list(conns))
    _Slots.looked = 0
    wait_lockstep(server, SETTINGS)  # type: ignore[arg-type]
    assert server.polls == 8 and not book.owing and not server.awaiting_answers
    assert _Slots.looked == 0  # one look at the book per wake-up, not one per robot
    # every client answered: no wait at all
    assert wait_lockstep(server, SETTINGS) == 0.0  # type: ignore[arg-type]
    assert server.polls == 8 and _Slots.looked == 0
