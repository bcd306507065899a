"""Plain lockstep sends a steady step's frames as views of one buffer the next step overwrites
(:meth:`Connection.send` of a ``memoryview``): what the socket does not take at once is
copied, so the client gets the bytes of the step it was sent, whole and in order, whatever the
buffer holds later."""

from __future__ import annotations

import socket
from collections.abc import Iterator

import pytest

from simulator.api.connection import Connection
from simulator.api.framing import HEADER

from .conftest import connection_pair


@pytest.fixture
def pair() -> Iterator[tuple[Connection, socket.socket]]:
    with connection_pair(send_buffer=4096) as both:  # a frame the socket cannot take
        yield both


def _framed(fill: int, size: int) -> bytearray:
    return bytearray(HEADER.pack(size) + bytes([fill]) * size)


def _receive(theirs: socket.socket, size: int) -> bytes:
    theirs.settimeout(5.0)
    data = b""
    while len(data) < size:
        chunk = theirs.recv(size - len(data))
        assert chunk, "closed early"
        data += chunk
    return data


def test_a_partly_written_view_is_sent_as_it_was(pair: tuple[Connection, socket.socket]) -> None:
    conn, theirs = pair
    size = 1 << 20  # far above the socket's buffer: a partial write
    buffer = _framed(1, size)
    conn.send(memoryview(buffer), 0.0)
    assert conn.want_write and not conn.idle  # the rest is kept
    buffer[:] = _framed(2, size)  # the next step overwrites the buffer
    second = _framed(3, 100)
    conn.send(memoryview(second), 0.0)  # queued behind the first: copied too
    second[:] = _framed(4, 100)
    received = b""
    while not conn.idle:
        received += _receive(theirs, 1)
        theirs.setblocking(False)
        try:
            while chunk := theirs.recv(1 << 16):
                received += chunk
        except BlockingIOError:
            pass
        conn.flush()
    rest = HEADER.size * 2 + size + 100 - len(received)
    received += _receive(theirs, rest) if rest else b""
    assert received == bytes(_framed(1, size)) + bytes(_framed(3, 100))
    assert conn.stats.messages_out == 2 and conn.measurements == 2


def test_a_whole_write_keeps_nothing(pair: tuple[Connection, socket.socket]) -> None:
    conn, theirs = pair
    buffer = _framed(5, 200)
    conn.send(memoryview(buffer)[: HEADER.size + 200], 0.0)
    assert conn.idle and not conn.want_write and conn.last_sent_at is not None
    assert _receive(theirs, HEADER.size + 200) == bytes(_framed(5, 200))
    assert not conn.answered  # the client owes its answer
