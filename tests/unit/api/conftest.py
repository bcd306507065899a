"""What the API's unit tests share: a :class:`Connection` on one end of a socket pair, the
client's end beside it, and a read that waits for a request the client sent."""

from __future__ import annotations

import socket
import time
from collections.abc import Iterator
from contextlib import contextmanager

from simulator.api.connection import Connection
from simulator.api.stats import RobotStats


@contextmanager
def connection_pair(
    *, key: str = "red 1", queue_limit: int = 10, threaded: bool = False,
    stats: RobotStats | None = None, send_buffer: int | None = None,
) -> Iterator[tuple[Connection, socket.socket]]:
    """The server's connection (non-blocking; its socket's send buffer ``send_buffer`` bytes
    when given) and the client's socket; both closed at the end."""
    ours, theirs = socket.socketpair()
    ours.setblocking(False)
    if send_buffer is not None:
        ours.setsockopt(socket.SOL_SOCKET, socket.SO_SNDBUF, send_buffer)
    conn = Connection(sock=ours, peer="test", key=key, stats=stats or RobotStats(),
                      queue_limit=queue_limit, time_bank_s=1.0, threaded=threaded)  # fmt: skip
    try:
        yield conn, theirs
    finally:
        ours.close()
        theirs.close()


def read_sent(conn: Connection, theirs: socket.socket, frame: bytes) -> int:
    """Send ``frame`` from the client and read until the connection takes something: the
    number of requests taken."""
    theirs.sendall(frame)
    for _ in range(200):
        taken = conn.read(time.monotonic())
        if taken:
            return taken
        time.sleep(0.005)
    raise AssertionError("the request did not arrive")
