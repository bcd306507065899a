"""A thread that does the clients' socket I/O in async and pipelined stepping.

A kernel ``send`` and ``recv`` per client per step are most of the robot API's cost on the
step thread. With this thread the step thread only reads the step's sensor values, hands the
step's measurements over (:meth:`SendThread.submit`: this thread writes their wire bytes, frames
them, counts them in each robot's quota and appends each to its connection's bounded queue) and
takes the requests this thread has decoded (:meth:`Connection.take_requests`); that work, the
writes and the reads happen while the step thread is back in the physics (MuJoCo releases the
GIL while it steps). A step thread more than ``MAX_JOBS`` steps ahead waits for this thread.
A client that does not read only fills its own queue (the oldest measurements are
dropped and counted as before). A socket error, end of stream or bad frame is left on the
connection (``error``) for the step thread to drop it, logged once there. An unexpected error
ends the thread and is kept in ``failure``; the server raises it at its next step
(:class:`simulator.api.server.IoThreadFailed`), as no client would hear from it again.

Waking this thread costs the step thread a write to a pipe that another CPU sleeps on: about
14 us of CPU on our virtual machines (the idle CPU halts, and the wake-up is an interrupt
between processors that exits to the host), 2% of an eight-robot step; the write alone, with
nobody asleep on the pipe, costs about 1.3 us (an ``eventfd`` instead of the pipe costs the same:
7-11 against 8-9 us a wake-up in one measurement). When the steps come faster than
``POLL_BELOW_S`` apart (a world running faster than real time) and ``poll`` is on, the thread
instead learns the period of the steps from when their frames were queued and sleeps until
``POLL_LATE_S`` after the next step's frames are due: the step thread writes nothing, and a
measurement leaves about that much later (then every ``POLL_MIN_S`` while a step is late). For
slower steps (a slower machine, a match paced to real time) the thread plans the same look, and
again every ``POLL_MIN_S`` until the step is ``LATE_SHARE`` of a period late, but the step thread
still wakes it unless that look is at most ``LOOK_AHEAD_S`` away: a measurement never waits
for a planned look longer than that. (Waiting for the look whatever its distance saved four
wake-ups in five on a loaded 2-core host, but the measurements of the steps that came early
waited for it: pipelined round trips of 4.2 ms against 1.5 ms.)

Its selector is ``select(2)``, whose timeout has microsecond resolution: ``epoll_wait`` counts
whole milliseconds, which would hold each polled measurement back a millisecond, longer than
an eight-robot step. (A descriptor number over ``select``'s limit switches it to the default
selector.)
"""

from __future__ import annotations

import logging
import os
import selectors
import threading
import time
from collections import deque
from collections.abc import Callable, Iterable
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from simulator.api.connection import Connection

log = logging.getLogger(__name__)

IDLE_WAIT_S = 0.05  # the longest the thread sleeps without being woken
POLL_BELOW_S = 0.002  # steps closer than this: the thread polls (when ``poll`` is on)
POLL_MIN_S = 0.0001  # shortest sleep between polls
POLL_LATE_S = 0.00003  # polled this long after a step's frames are due (the step's jitter)
LATE_SHARE = 0.125  # slower steps: looked for until this share of a period late, then woken
LOOK_AHEAD_S = 0.0001  # slower steps: no wake-up when the thread looks by itself this soon
NO_LOOK = float("inf")  # no look planned
PAUSED_WAIT_S = 0.002  # the longest sleep while a client is paused for its budget
MAX_JOBS = 2  # jobs waiting before submit waits (this step's, and the previous one still running)
PERIOD_SAMPLES = 6  # the period of the steps: the median of the last intervals between them
SELECT_FD_LIMIT = 1024  # FD_SETSIZE: select(2) takes descriptor numbers below it
READ = selectors.EVENT_READ
WRITE = selectors.EVENT_WRITE


class SendThread:
    """Reads and writes the sockets of the connections added to it. ``cpus``: where it runs."""

    def __init__(
        self,
        *,
        cpus: Iterable[int] | None = None,
        on_news: Callable[[], None] | None = None,
        poll: bool = False,
    ) -> None:
        """``on_news``: called (on this thread) after a read that brought requests or found a
        failure, so that a step thread waiting for answers (pipelined lockstep) wakes up.
        ``poll``: when steps come fast, look at the queues right after each step's frames are
        due instead of being woken."""
        self._on_news = on_news
        self._ready: deque[Connection] = deque()
        self._jobs: deque[Callable[[], Iterable[Connection]]] = deque()
        self._changes: deque[tuple[bool, Connection]] = deque()  # (add?, connection)
        self._wake_r, self._wake_w = os.pipe()
        os.set_blocking(self._wake_r, False)
        os.set_blocking(self._wake_w, False)
        # a wake byte is in the pipe and not read yet (plain flags: the GIL orders them)
        self._woken = False
        # the thread is in (or about to enter) its select: a wake-up needs the pipe; when it is
        # busy it looks at the queues before it sleeps again, so a wake-up is not needed (a
        # write to a pipe another CPU waits on costs the writer about 14 us of CPU)
        self._sleeping = False
        # the thread looks at the queues by itself when the next step's frames are due: no
        # wake-up needed
        self._polling = False
        # slower steps: when the thread looks at the queues by itself next (inf: it does not)
        self._look_at = NO_LOOK
        self.wakes = 0  # pipe writes so far (each costs the writer a wake-up of this thread)
        self._poll = poll
        self._stop = False
        # what ended the thread early; the step thread raises it (every client's measurements
        # would stop otherwise, and the match go on blind)
        self.failure: Exception | None = None
        self._cpus = frozenset(cpus) if cpus else None
        self._thread = threading.Thread(target=self._run, name="api-io", daemon=True)
        self._thread.start()

    def add(self, conn: Connection) -> None:
        self._changes.append((True, conn))
        self._signal()

    def remove(self, conn: Connection) -> None:
        """Forget ``conn`` (before the step thread closes it)."""
        self._changes.append((False, conn))
        self._signal()

    def wake(self, connections: Iterable[Connection]) -> None:
        """The connections have new frames queued."""
        self._ready.extend(connections)
        self._signal()

    def submit(self, job: Callable[[], Iterable[Connection]]) -> None:
        """Run ``job`` on this thread (jobs in the order submitted), then write to the
        connections it returns: the step thread hands over a step's framing and queueing.
        When this thread is more than ``MAX_JOBS`` jobs behind, the caller waits for it (the
        steps then go at the pace this thread delivers them, and the jobs waiting are
        bounded)."""
        self._jobs.append(job)
        self._signal()
        while len(self._jobs) > MAX_JOBS and self.failure is None and self._thread.is_alive():
            time.sleep(POLL_MIN_S)  # releases the GIL: this thread catches up

    def close(self) -> None:
        self._stop = True
        self._signal()
        self._thread.join(timeout=5.0)
        os.close(self._wake_r)
        os.close(self._wake_w)

    def _signal(self) -> None:
        if self._woken or not self._sleeping or self._polling:
            return  # one byte in the pipe is enough; a busy or polling thread sees the queues
        if time.monotonic() >= self._look_at - LOOK_AHEAD_S:
            return  # it looks at the queues by itself in a moment
        self._woken = True
        self.wakes += 1
        try:
            os.write(self._wake_w, b"\0")
        except BlockingIOError:
            pass  # the pipe is full of wake-ups already

    def _run(self) -> None:
        """The thread's loop: plan the next look (polling), wait on the sockets and the wake-up
        pipe, run the step thread's jobs, read and write the ready sockets (see the module)."""
        self._pin_cpus()
        masks: dict[Connection, int] = {}
        selector: selectors.BaseSelector = selectors.SelectSelector()
        selector.register(self._wake_r, READ, None)
        try:
            on_news = self._on_news
            poll = self._poll
            last_frames = interval = 0.0  # when frames were last found queued, and the step
            queued: deque[float] = deque(maxlen=PERIOD_SAMPLES)  # when the step thread queued
            period = 0.0
            paused: list[Connection] = []  # clients whose budget is spent, not read for now
            while not self._stop:
                look = NO_LOOK
                if poll:  # decided before the queues are looked at, as ``_sleeping``
                    now = time.monotonic()
                    since = now - last_frames
                    self._polling = interval < POLL_BELOW_S and since < POLL_BELOW_S
                    if not self._polling and looks(since, interval, period):
                        look = max(now + POLL_MIN_S, queued[-1] + period + POLL_LATE_S)
                self._look_at = look
                self._sleeping = True  # before the queues are looked at: see _signal
                busy = bool(self._ready or self._changes or self._jobs)
                if busy:
                    timeout = 0.0
                elif self._polling:  # just after the step thread queues the next frames
                    timeout = max(POLL_MIN_S, queued[-1] + period + POLL_LATE_S - now)
                elif look != NO_LOOK:  # slower steps: the planned look (``now`` is set)
                    timeout = max(POLL_MIN_S, look - now)  # (now + x) - now may be under x
                else:
                    timeout = IDLE_WAIT_S
                if paused and timeout > PAUSED_WAIT_S:
                    timeout = PAUSED_WAIT_S  # read again soon after the budget refills
                try:
                    ready = selector.select(timeout)
                except OSError:  # a socket closed before its removal reached this thread
                    if not any(conn.closed for conn in masks):
                        raise  # not that: retrying would spin, so the thread fails loudly
                    self._sleeping = False
                    selector = self._forget_closed(selector, masks)
                    continue
                self._sleeping = False
                while self._jobs:
                    self._ready.extend(self._jobs.popleft()())
                if poll and self._ready:
                    now = time.monotonic()
                    interval, last_frames = now - last_frames, now
                    period = self._learn_period(queued)
                news = self._on_ready(ready, selector, masks, paused)
                if paused:
                    news = self._resume(selector, masks, paused) or news
                if news and on_news is not None:
                    on_news()
                selector = self._apply_changes(selector, masks)
                self._write_ready(selector, masks)
        except Exception as exc:  # no client would hear from the simulator again: say so
            self.failure = exc
            log.exception("robot API I/O thread failed")
            if self._on_news is not None:
                self._on_news()  # a step thread waiting for answers wakes and finds it
        finally:
            selector.close()

    def _pin_cpus(self) -> None:
        """Run this thread only on the CPUs it was given (a warning when it cannot)."""
        if self._cpus:
            try:
                os.sched_setaffinity(0, self._cpus)  # this thread only
            except OSError as exc:
                log.warning("robot API I/O thread: cannot run on CPUs %s: %s",
                            sorted(self._cpus), exc)  # fmt: skip

    def _on_ready(
        self,
        ready: list[tuple[selectors.SelectorKey, int]],
        selector: selectors.BaseSelector,
        masks: dict[Connection, int],
        paused: list[Connection],
    ) -> bool:
        """Handle what ``select`` found: drain the wake-up pipe, read the readable clients
        (pausing those whose budget is spent), queue the writable ones for writing. True when
        a read brought requests."""
        news = False
        for key, events in ready:
            conn = key.data
            if conn is None:  # drain, then clear: a wake-up after this is not lost
                try:
                    os.read(self._wake_r, 4096)
                except BlockingIOError:
                    pass
                self._woken = False
                continue
            if events & READ and conn.error is None:
                news = conn.read_threaded(time.monotonic()) or news
                if conn.paused:  # its budget is spent: not watched until it refills
                    paused.append(conn)
                    self._set_mask(selector, masks, conn)
            if events & WRITE:
                self._ready.append(conn)
        return news

    def _resume(
        self,
        selector: selectors.BaseSelector,
        masks: dict[Connection, int],
        paused: list[Connection],
    ) -> bool:
        """Read again the paused connections whose budget refilled (``paused`` keeps the
        others); True when that brought requests or a failure."""
        news = False
        now = time.monotonic()
        waiting = [conn for conn in paused if conn in masks and not conn.closed]
        paused.clear()
        for conn in waiting:
            if not conn.resume(now):
                paused.append(conn)
                continue
            self._set_mask(selector, masks, conn)
            news = conn.read_threaded(now) or news  # frames may be buffered: select cannot tell
            if conn.paused:
                paused.append(conn)
                self._set_mask(selector, masks, conn)
        return news

    def _set_mask(
        self,
        selector: selectors.BaseSelector,
        masks: dict[Connection, int],
        conn: Connection,
        writing: bool | None = None,
    ) -> None:
        """Watch ``conn`` for reading unless paused, and for writing when ``writing`` (None:
        as now); a socket watched for neither is unregistered."""
        old = masks.get(conn)
        if old is None:
            return  # removed
        if writing is None:
            writing = bool(old & WRITE)
        wanted = (0 if conn.paused else READ) | (WRITE if writing else 0)
        if wanted == old:
            return
        masks[conn] = wanted
        try:
            if not old:
                selector.register(conn.fd, wanted, conn)
            elif not wanted:
                selector.unregister(conn.fd)
            else:
                selector.modify(conn.fd, wanted, conn)
        except (KeyError, ValueError, OSError):
            pass  # closed meanwhile; its removal follows

    def _learn_period(self, queued: deque[float]) -> float:
        """Note when the step thread queued the frames just found (the newest connection's
        ``enqueued_at``); the median interval between the latest such times, the period of the
        steps."""
        at = self._ready[-1].enqueued_at
        if not queued or at > queued[-1]:
            queued.append(at)
        if len(queued) < 2:
            return 0.0
        times = list(queued)
        gaps = sorted(b - a for a, b in zip(times, times[1:], strict=False))
        return gaps[len(gaps) // 2]

    def _apply_changes(
        self, selector: selectors.BaseSelector, masks: dict[Connection, int]
    ) -> selectors.BaseSelector:
        """Register and unregister the connections added and removed; the selector to use
        from now on."""
        while self._changes:
            add, conn = self._changes.popleft()
            if add:
                if conn.closed:
                    continue
                if conn.fd >= SELECT_FD_LIMIT and isinstance(selector, selectors.SelectSelector):
                    selector = self._without_select(selector, masks)
                try:
                    selector.register(conn.fd, READ, conn)
                    masks[conn] = READ
                except (KeyError, ValueError, OSError) as exc:
                    conn.error = f"cannot watch the socket: {exc}"
            elif conn in masks:
                _unwatch(selector, masks, conn)
        return selector

    def _forget_closed(
        self, selector: selectors.BaseSelector, masks: dict[Connection, int]
    ) -> selectors.BaseSelector:
        """Unregister the connections the step thread has closed. ``select(2)`` fails on a
        closed descriptor (``epoll`` forgets it by itself), and the step thread closes a
        dropped connection right after asking this thread to forget it."""
        selector = self._apply_changes(selector, masks)
        for conn in [conn for conn in masks if conn.closed]:
            _unwatch(selector, masks, conn)
        return selector

    def _without_select(
        self, selector: selectors.BaseSelector, masks: dict[Connection, int]
    ) -> selectors.BaseSelector:
        """The default selector watching what ``selector`` watched (which is closed)."""
        log.info("robot API I/O thread: a descriptor above %d, polled in whole milliseconds",
                 SELECT_FD_LIMIT - 1)  # fmt: skip
        replacement = selectors.DefaultSelector()
        replacement.register(self._wake_r, READ, None)
        for conn, mask in masks.items():
            if mask:  # (0: a paused connection with nothing to write)
                replacement.register(conn.fd, mask, conn)
        selector.close()
        return replacement

    def _write_ready(
        self, selector: selectors.BaseSelector, masks: dict[Connection, int]
    ) -> None:
        while self._ready:
            conn = self._ready.popleft()
            mask = masks.get(conn)
            if mask is None:
                continue  # removed
            wanted = (0 if conn.paused else READ) | (0 if conn.write_queued() else WRITE)
            if wanted != mask:
                self._set_mask(selector, masks, conn, writing=bool(wanted & WRITE))


def looks(since: float, interval: float, period: float) -> bool:
    """Slower steps: whether the thread plans a look at the queues for the next step's frames
    (``since`` the last frames were found, ``interval`` between the last two findings,
    ``period`` of the steps, 0 while not known yet)."""
    if interval < POLL_BELOW_S:
        return False  # fast steps: polled (``POLL_BELOW_S``)
    return 0.0 < period and since < period * (1.0 + LATE_SHARE)


def _unwatch(
    selector: selectors.BaseSelector, masks: dict[Connection, int], conn: Connection
) -> None:
    del masks[conn]
    try:
        selector.unregister(conn.fd)
    except (KeyError, ValueError, OSError):
        pass  # closed already: the kernel forgot it
