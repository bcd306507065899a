"""A thread that writes queued measurements to the clients' sockets (async stepping).

One kernel ``send`` per client per step is most of the robot API's cost on the step thread.
In async mode the step thread only appends each framed measurement to its connection's bounded
queue (:meth:`simulator.api.connection.Connection.send`) and wakes this thread, which writes
while the step thread is back in the physics (MuJoCo releases the GIL while it steps). A client
that does not read only fills its own queue; the oldest measurements are dropped and counted
as before. A socket error is left on the connection for the step thread to drop it.
"""

from __future__ import annotations

import logging
import os
import selectors
import threading
from collections import deque
from collections.abc import Iterable
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from simulator.api.connection import Connection

log = logging.getLogger(__name__)

IDLE_WAIT_S = 0.05  # how long a blocked socket is waited for before queues are looked at again


class SendThread:
    """Writes the queues of the connections it is woken for. ``cpus``: where it may run."""

    def __init__(self, *, cpus: Iterable[int] | None = None) -> None:
        self._ready: deque[Connection] = deque()
        self._wake = threading.Event()
        self._stop = False
        self._cpus = frozenset(cpus) if cpus else None
        self._thread = threading.Thread(target=self._run, name="api-send", daemon=True)
        self._thread.start()

    def wake(self, connections: Iterable[Connection]) -> None:
        """The connections have new frames queued."""
        self._ready.extend(connections)
        self._wake.set()

    def close(self) -> None:
        self._stop = True
        self._wake.set()
        self._thread.join(timeout=5.0)

    def _run(self) -> None:
        if self._cpus:
            try:
                os.sched_setaffinity(0, self._cpus)  # this thread only
            except OSError as exc:
                log.warning("send thread: cannot run on CPUs %s: %s", sorted(self._cpus), exc)
        blocked: dict[Connection, None] = {}  # sockets that took only part of a frame
        with selectors.DefaultSelector() as selector:
            while not self._stop:
                if blocked:
                    for key, _ in selector.select(IDLE_WAIT_S if not self._ready else 0.0):
                        self._ready.append(key.data)
                else:
                    self._wake.wait(IDLE_WAIT_S)
                self._wake.clear()
                while self._ready:
                    conn = self._ready.popleft()
                    was_blocked = conn in blocked
                    if conn.write_queued():
                        if was_blocked:
                            del blocked[conn]
                            _unregister(selector, conn)
                    elif not was_blocked and not conn.closed:
                        blocked[conn] = None
                        try:
                            selector.register(conn.sock, selectors.EVENT_WRITE, conn)
                        except (ValueError, KeyError, OSError):
                            del blocked[conn]  # closed meanwhile
                for conn in [c for c in blocked if c.closed]:
                    del blocked[conn]
                    _unregister(selector, conn)


def _unregister(selector: selectors.BaseSelector, conn: Connection) -> None:
    try:
        selector.unregister(conn.fd)  # by number: the socket may be closed already
    except (KeyError, ValueError, OSError):
        pass  # closed by the step thread already
