"""A thread that does the clients' socket I/O in async stepping.

A kernel ``send`` and ``recv`` per client per step are most of the robot API's cost on the
step thread. In async mode the step thread only appends each framed measurement to its
connection's bounded queue (:meth:`simulator.api.connection.Connection.send`), wakes this thread
and takes the requests this thread has decoded (:meth:`Connection.take_requests`); the writes
and reads happen while the step thread is back in the physics (MuJoCo releases the GIL while it
steps). A client that does not read only fills its own queue (the oldest measurements are
dropped and counted as before). A socket error, end of stream or bad frame is left on the
connection (``error``) for the step thread to drop it, logged once there.

Waking this thread costs the step thread a write to a pipe that another CPU sleeps on: about
18 us on our virtual machines (the idle CPU halts, and the wake-up is an interrupt between
processors that exits to the host), 2% of an eight-robot step. When the steps come faster than
``POLL_BELOW_S`` apart (a world running faster than real time) and ``poll`` is on, the thread
instead sleeps half the last interval between steps and looks at the queues by itself: the step
thread writes nothing, and a measurement leaves at most half a step's wall time later (about
0.5 ms at eight times real time). Slower steps (a match paced to real time) wake it as before.
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
        failure, so that a step thread waiting for answers (lockstep) wakes up. ``poll``: look
        at the queues every half step instead of being woken when steps come fast (async
        stepping, where nobody waits for the answers)."""
        self._on_news = on_news
        self._ready: deque[Connection] = deque()
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
        # the thread sleeps at most half a step and looks at the queues then: no wake-up needed
        self._polling = False
        self._poll = poll
        self._stop = False
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

    def close(self) -> None:
        self._stop = True
        self._signal()
        self._thread.join(timeout=5.0)
        os.close(self._wake_r)
        os.close(self._wake_w)

    def _signal(self) -> None:
        if self._woken or not self._sleeping or self._polling:
            return  # one byte in the pipe is enough; a busy or polling thread sees the queues
        self._woken = True
        try:
            os.write(self._wake_w, b"\0")
        except BlockingIOError:
            pass  # the pipe is full of wake-ups already

    def _run(self) -> None:
        if self._cpus:
            try:
                os.sched_setaffinity(0, self._cpus)  # this thread only
            except OSError as exc:
                log.warning("robot API I/O thread: cannot run on CPUs %s: %s",
                            sorted(self._cpus), exc)  # fmt: skip
        masks: dict[Connection, int] = {}
        with selectors.DefaultSelector() as selector:
            selector.register(self._wake_r, READ, None)
            on_news = self._on_news
            poll = self._poll
            last_frames = interval = 0.0  # when frames were last found queued, and the step
            while not self._stop:
                news = False
                if poll:  # decided before the queues are looked at, as ``_sleeping``
                    now = time.monotonic()
                    self._polling = interval < POLL_BELOW_S and now - last_frames < POLL_BELOW_S
                self._sleeping = True  # before the queues are looked at: see _signal
                busy = bool(self._ready or self._changes)
                if busy:
                    timeout = 0.0
                elif self._polling:
                    timeout = max(POLL_MIN_S, interval / 2)
                else:
                    timeout = IDLE_WAIT_S
                ready = selector.select(timeout)
                self._sleeping = False
                if poll and self._ready:
                    now = time.monotonic()
                    interval, last_frames = now - last_frames, now
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
                    if events & WRITE:
                        self._ready.append(conn)
                if news and on_news is not None:
                    on_news()
                self._apply_changes(selector, masks)
                self._write_ready(selector, masks)

    def _apply_changes(
        self, selector: selectors.BaseSelector, masks: dict[Connection, int]
    ) -> None:
        while self._changes:
            add, conn = self._changes.popleft()
            if add:
                if conn.closed:
                    continue
                try:
                    selector.register(conn.fd, READ, conn)
                    masks[conn] = READ
                except (KeyError, ValueError, OSError) as exc:
                    conn.error = f"cannot watch the socket: {exc}"
            elif conn in masks:
                del masks[conn]
                try:
                    selector.unregister(conn.fd)
                except (KeyError, ValueError, OSError):
                    pass  # closed already: the kernel forgot it

    def _write_ready(
        self, selector: selectors.BaseSelector, masks: dict[Connection, int]
    ) -> None:
        while self._ready:
            conn = self._ready.popleft()
            mask = masks.get(conn)
            if mask is None:
                continue  # removed
            wanted = READ if conn.write_queued() else READ | WRITE
            if wanted != mask:
                masks[conn] = wanted
                try:
                    selector.modify(conn.fd, wanted, conn)
                except (KeyError, ValueError, OSError):
                    pass  # closed meanwhile; its removal follows
