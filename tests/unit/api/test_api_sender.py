"""The I/O thread of async and pipelined stepping: frames queued by the step thread all reach
the client, in order; when steps come fast the thread polls and the step thread stops waking it
(no write to the wake pipe), and its polled waits follow the steps' period with sub-millisecond
timeouts; when steps come slowly (a match paced to real time) a step wakes it unless the thread
looks at the queues by itself in a moment. A socket whose descriptor number ``select`` cannot
watch is served too."""

from __future__ import annotations

import os
import resource
import selectors
import socket
import threading
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
    monkeypatch: pytest.MonkeyPatch, arrived: list[bool] | None = None,
) -> int:  # fmt: skip
    """Queue one frame per step, ``gap_s`` apart; the number of wake-up writes. ``arrived``:
    per step, whether its frame had reached the client when the next one was queued."""
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
    received = b""
    sent = 0
    try:
        for frame in frames:
            if arrived is not None:  # what reached the client of the frames queued so far
                client.setblocking(False)
                try:
                    received += client.recv(65536)
                except BlockingIOError:
                    pass
                if sent:
                    arrived.append(len(received) == sent)
            conn.send_threaded(frame, time.monotonic())
            sent += len(frame)
            thread.wake([conn])
            time.sleep(gap_s)  # a step of physics (which releases the GIL, as sleeping does)
        expected = b"".join(frames)
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


def test_slow_steps_skip_the_wake_up_when_the_thread_looks_in_a_moment(
    pair: tuple[Connection, socket.socket], monkeypatch: pytest.MonkeyPatch
) -> None:
    """Steps 5 ms apart: the thread plans a look at the queues 30 us after the next step is
    due, and a step thread whose frames come within ``LOOK_AHEAD_S`` of that look (or later,
    while the thread looks again every ``POLL_MIN_S``) does not wake it. With a look-ahead of
    a whole step no step wakes it once it knows the period (each one did before)."""
    conn, client = pair
    monkeypatch.setattr(sender_module, "LOOK_AHEAD_S", 0.006)
    wakes = _run(conn, client, poll=True, steps=20, gap_s=0.005, monkeypatch=monkeypatch)
    assert wakes < 10, wakes  # the first steps, before the period is known


@pytest.mark.parametrize(
    ("since", "interval", "period", "looked"),
    [
        (0.0005, 0.0008, 0.0008, False),  # fast steps: polled instead
        (0.0040, 0.0050, 0.0050, True),  # slower steps: looked for when the step is due
        (0.0056, 0.0050, 0.0050, True),  # ... and until an eighth of a period late
        (0.0057, 0.0050, 0.0050, False),  # later: woken by the step thread
        (0.0010, 0.0500, 0.0, False),  # no period known yet: woken
    ],
)
def test_when_the_thread_plans_a_look(
    since: float, interval: float, period: float, looked: bool
) -> None:
    assert sender_module.looks(since, interval, period) is looked


def test_without_poll_fast_steps_wake_the_thread(
    pair: tuple[Connection, socket.socket], monkeypatch: pytest.MonkeyPatch
) -> None:
    conn, client = pair
    wakes = _run(conn, client, poll=False, steps=100, gap_s=0.001, monkeypatch=monkeypatch)
    assert wakes >= 50, wakes  # the thread sleeps between steps: woken (most) every step


def test_polled_waits_are_sub_millisecond_selects(
    pair: tuple[Connection, socket.socket], monkeypatch: pytest.MonkeyPatch
) -> None:
    """Steps 0.5 ms apart (a world 16 times faster than real time): the thread polls just
    after each step's frames are due, with waits shorter than a millisecond given to
    ``select(2)``, whose timeout has microsecond resolution. (``epoll_wait`` counts whole
    milliseconds: each polled frame would leave a step late.) How many frames leave within
    their step on a given machine is a benchmark's figure, not this test's."""
    conn, client = pair
    waits: list[tuple[str, float | None]] = []
    real_select = selectors.SelectSelector.select

    def select(self: selectors.SelectSelector, timeout: float | None = None):  # type: ignore[no-untyped-def]
        waits.append((type(self).__name__, timeout))
        return real_select(self, timeout)

    monkeypatch.setattr(selectors.SelectSelector, "select", select)
    wakes = _run(conn, client, poll=True, steps=300, gap_s=0.0005, monkeypatch=monkeypatch)
    assert wakes < 150, wakes  # polled, not woken
    # polled: sub-millisecond timeouts, which select(2) keeps and epoll_wait would round up
    # (a step that came late, on a loaded machine, is looked for later: a longer wait)
    polled = [t for _, t in waits if t is not None and 0.0 < t < 0.001]
    assert len(polled) >= 30, waits[:50]  # the thread polled between many steps
    assert all(name == "SelectSelector" for name, _ in waits)
    assert all(t >= sender_module.POLL_MIN_S for t in polled), sorted(polled)[:5]
    assert any(t > sender_module.POLL_MIN_S for t in polled), polled[:20]  # aimed, not fixed


def test_a_descriptor_beyond_select_is_served(monkeypatch: pytest.MonkeyPatch) -> None:
    """A connection whose socket's descriptor number is above what ``select(2)`` takes (a
    process with many files open): the thread moves to the default selector and serves it."""
    high_fd = sender_module.SELECT_FD_LIMIT + 10
    soft, hard = resource.getrlimit(resource.RLIMIT_NOFILE)
    if soft <= high_fd:  # a descriptor that high needs the limit above it
        if hard != resource.RLIM_INFINITY and hard <= high_fd:
            pytest.skip(f"the hard limit of open files ({hard}) is below {high_fd + 1}")
        resource.setrlimit(resource.RLIMIT_NOFILE, (high_fd + 1, hard))
    ours, theirs = socket.socketpair()
    try:
        high = os.dup2(ours.fileno(), high_fd)
        ours.close()
        sock = socket.socket(fileno=high)
        sock.setblocking(False)
        conn = Connection(
            sock=sock, peer="test", key="red 1", stats=RobotStats(), queue_limit=1000,
            time_bank_s=1.0, threaded=True,
        )  # fmt: skip
        try:
            _run(conn, theirs, poll=True, steps=50, gap_s=0.0005, monkeypatch=monkeypatch)
            assert conn.error is None
        finally:
            sock.close()
    finally:
        theirs.close()
        resource.setrlimit(resource.RLIMIT_NOFILE, (soft, hard))


def test_a_connection_closed_before_its_removal_arrives_does_not_stop_the_thread() -> None:
    """The step thread drops a client by asking the thread to forget it and closing the socket
    at once; ``select(2)`` fails on the closed descriptor if the thread is already waiting on
    it. The thread forgets it and goes on serving the other clients (it used to die, and every
    robot's measurements stopped)."""
    thread = SendThread(poll=False)
    pairs = [socket.socketpair() for _ in range(2)]
    conns = []
    for ours, _ in pairs:
        ours.setblocking(False)
        conns.append(Connection(
            sock=ours, peer="test", key="red 1", stats=RobotStats(), queue_limit=1000,
            time_bank_s=1.0, threaded=True,
        ))  # fmt: skip
    try:
        for conn in conns:
            thread.add(conn)
        time.sleep(0.1)  # both registered; the thread waits in select on them
        # closed before the thread takes its removal (when the thread was busy as the step
        # thread asked): its next select sees a closed descriptor
        conns[0].close()
        time.sleep(2 * sender_module.IDLE_WAIT_S)
        thread.remove(conns[0])
        time.sleep(0.1)
        assert thread._thread.is_alive()
        frame = b"\0\0\0\x05hello"
        conns[1].send_threaded(frame, time.monotonic())
        thread.wake([conns[1]])
        client = pairs[1][1]
        client.settimeout(5.0)
        assert client.recv(64) == frame
    finally:
        thread.close()
        for ours, theirs in pairs:
            ours.close()
            theirs.close()


def test_an_unexpected_error_is_kept_for_the_step_thread(
    pair: tuple[Connection, socket.socket], monkeypatch: pytest.MonkeyPatch
) -> None:
    """A bug in the thread's loop ends it, but not silently: the error is logged, kept in
    ``failure`` and the step thread's wait is woken (the server raises it on its next step)."""
    conn, client = pair
    news: list[bool] = []
    thread = SendThread(poll=False, on_news=lambda: news.append(True))

    def broken(now: float) -> bool:
        raise RuntimeError("a bug")

    monkeypatch.setattr(conn, "read_threaded", broken)
    try:
        thread.add(conn)
        client.sendall(b"\0\0\0\x02ab")
        deadline = time.monotonic() + 5
        while thread._thread.is_alive() and time.monotonic() < deadline:
            time.sleep(0.01)
        assert isinstance(thread.failure, RuntimeError)
        assert news == [True]
    finally:
        thread.close()


def test_a_select_failure_without_a_closed_socket_fails_the_thread(
    pair: tuple[Connection, socket.socket], monkeypatch: pytest.MonkeyPatch
) -> None:
    """A ``select`` error that no closed connection explains is the thread's failure (kept for
    the step thread), not retried forever."""
    conn, _client = pair

    def failing(self: object, timeout: float | None = None) -> list[object]:
        raise OSError(22, "Invalid argument")

    monkeypatch.setattr(selectors.SelectSelector, "select", failing)
    thread = SendThread(poll=False)
    try:
        thread.add(conn)
        thread._thread.join(timeout=5)
        assert not thread._thread.is_alive()
        assert isinstance(thread.failure, OSError)
    finally:
        thread.close()


def test_submitted_jobs_run_in_order_and_their_frames_are_written(
    pair: tuple[Connection, socket.socket],
) -> None:
    """The step thread hands a step's framing over as a job: the jobs run on the thread in
    the order submitted, and the connections they return are written to."""
    conn, client = pair
    thread = SendThread(poll=True)
    thread.add(conn)
    ran: list[int] = []
    frames = [len(str(k)).to_bytes(4, "big") + str(k).encode() for k in range(200)]

    def job(k: int) -> list[Connection]:
        ran.append(k)
        conn.send_threaded(frames[k], time.monotonic())
        return [conn]

    try:
        for k in range(len(frames)):
            thread.submit(lambda k=k: job(k))
            time.sleep(0.0003)
        expected = b"".join(frames)
        received = b""
        client.settimeout(5.0)
        while len(received) < len(expected):
            received += client.recv(65536)
        assert received == expected
        assert ran == list(range(len(frames)))
    finally:
        thread.close()


def test_submit_waits_while_the_thread_is_behind() -> None:
    """A thread more than ``MAX_JOBS`` jobs behind holds the step thread back: the jobs
    waiting stay bounded (a world much faster than the thread would queue without end)."""
    thread = SendThread(poll=False)
    release = threading.Event()
    waiting: list[int] = []

    def slow() -> list[Connection]:
        release.wait(5.0)
        return []

    try:
        thread.submit(slow)  # the thread runs it and blocks
        time.sleep(0.05)
        for _ in range(sender_module.MAX_JOBS):
            thread.submit(lambda: [])
        done = threading.Event()

        def one_more() -> None:
            thread.submit(lambda: [])
            waiting.append(len(thread._jobs))
            done.set()

        threading.Thread(target=one_more, daemon=True).start()
        assert not done.wait(0.2)  # held back while the thread is behind
        release.set()
        assert done.wait(5.0)
        assert waiting[0] <= sender_module.MAX_JOBS
    finally:
        release.set()
        thread.close()
