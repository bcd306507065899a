"""The I/O thread of async stepping: frames queued by the step thread all reach the client, in
order; when steps come fast the thread polls and the step thread stops waking it (no write to
the wake pipe), when they come slowly (a match paced to real time) every step wakes it."""

from __future__ import annotations

import os
import socket
import time
from collections.abc import Iterator

import pytest

from simulator.api import sender as sender_module
from simulator.api.connection import Connection
from simulator.api.sender import SendThread
from simulator.api.stats import RobotStats


@pytest.fixture
def pair() -> Iterator[tuple[Connection, socket.socket]]:
    ours, theirs = socket.socketpair()
    ours.setblocking(False)
    conn = Connection(
        sock=ours, peer="test", key="red 1", stats=RobotStats(), queue_limit=1000,
        time_bank_s=1.0, threaded=True,
    )  # fmt: skip
    yield conn, theirs
    ours.close()
    theirs.close()


def _run(
    conn: Connection, client: socket.socket, *, poll: bool, steps: int, gap_s: float,
    monkeypatch: pytest.MonkeyPatch,
) -> int:  # fmt: skip
    """Queue one frame per step, ``gap_s`` apart; the number of wake-up writes."""
    wakes = [0]
    real_write = os.write
    thread = SendThread(poll=poll)

    def write(fd: int, data: bytes) -> int:
        if fd == thread._wake_w:
            wakes[0] += 1
        return real_write(fd, data)

    monkeypatch.setattr(sender_module.os, "write", write)
    thread.add(conn)
    frames = [len(str(k)).to_bytes(4, "big") + str(k).encode() for k in range(steps)]
    try:
        for frame in frames:
            conn.send_threaded(frame, time.monotonic())
            thread.wake([conn])
            time.sleep(gap_s)  # a step of physics (which releases the GIL, as sleeping does)
        expected = b"".join(frames)
        received = b""
        client.settimeout(5.0)
        while len(received) < len(expected):
            received += client.recv(65536)
        assert received == expected
    finally:
        thread.close()
    return wakes[0]


def test_fast_steps_are_polled_without_waking(
    pair: tuple[Connection, socket.socket], monkeypatch: pytest.MonkeyPatch
) -> None:
    conn, client = pair
    wakes = _run(conn, client, poll=True, steps=300, gap_s=0.0003, monkeypatch=monkeypatch)
    # a few while the interval is learned, or after a hiccup of a loaded machine (each step
    # wakes the thread without polling: 300)
    assert wakes < 150, wakes


def test_slow_steps_wake_the_thread_every_time(
    pair: tuple[Connection, socket.socket], monkeypatch: pytest.MonkeyPatch
) -> None:
    conn, client = pair
    wakes = _run(conn, client, poll=True, steps=20, gap_s=0.005, monkeypatch=monkeypatch)
    # steps 5 ms apart: no polling, each one wakes the thread (but when a loaded machine kept
    # the thread busy past the next step; with polling: 2 or 3)
    assert wakes >= 12, wakes


def test_without_poll_fast_steps_wake_the_thread(
    pair: tuple[Connection, socket.socket], monkeypatch: pytest.MonkeyPatch
) -> None:
    conn, client = pair
    wakes = _run(conn, client, poll=False, steps=100, gap_s=0.001, monkeypatch=monkeypatch)
    assert wakes >= 50, wakes  # the thread sleeps between steps: woken (most) every step
