"""``bench api --client one-process``: every robot's client served by one process.

Each robot's client is the minimal loop of a real one: it waits for a measurement and answers
it with joint targets (a one-second cycle of pre-encoded requests; measurements are framed but
not decoded). In the league each robot runs on its own computer; here the clients share the
bench machine's other CPUs. The default clients, one process per robot on one CPU, are woken,
switched to and put back to sleep by the kernel one after another; one process watching every
robot's socket (``epoll``) answers every measurement that has arrived in one wake-up, and the
server's sends wake one process instead of eight. It gets one process's share of a CPU that
other work also wants, where the default clients get eight.
"""

from __future__ import annotations

import os
import selectors
import socket
from collections.abc import Sequence

RECEIVE_BYTES = 1 << 20


class _Robot:
    """One robot's socket, its received bytes not yet framed and its answers."""

    __slots__ = ("answered", "buffer", "cycle", "sock")

    def __init__(self, sock: socket.socket, cycle: Sequence[bytes]) -> None:
        self.sock = sock
        self.cycle = cycle
        self.buffer = b""
        self.answered = 0

    def serve(self) -> bool:
        """Read what arrived and answer each whole measurement; False when the server closed."""
        try:
            data = self.sock.recv(RECEIVE_BYTES)
        except (BlockingIOError, InterruptedError):
            return True
        except OSError:
            return False
        if not data:
            return False
        buffer = self.buffer + data if self.buffer else data
        start, size = 0, len(buffer)
        while size - start >= 4:
            end = start + 4 + int.from_bytes(buffer[start : start + 4], "big")
            if end > size:
                break
            start = end
            answer = self.cycle[self.answered % len(self.cycle)]
            self.answered += 1
            try:
                sent = self.sock.send(answer)
                if sent < len(answer):  # the socket is full: rare, finish it blocking
                    self.sock.setblocking(True)
                    self.sock.sendall(answer[sent:])
                    self.sock.setblocking(False)
            except OSError:
                return False
        self.buffer = buffer[start:]
        return True


def serve_all(socks: Sequence[socket.socket], cycle: Sequence[bytes]) -> None:
    """Answer every measurement on ``socks`` (connected, greeted, sensors enabled) with the
    requests of ``cycle`` in turn, until the server closes them all; then exit the process."""
    robots = {}
    with selectors.DefaultSelector() as selector:
        for sock in socks:
            sock.setblocking(False)
            robots[sock.fileno()] = robot = _Robot(sock, cycle)
            selector.register(sock, selectors.EVENT_READ, robot)
        while robots:
            for key, _ in selector.select():
                robot = key.data
                if not robot.serve():
                    selector.unregister(robot.sock)
                    robots.pop(robot.sock.fileno(), None)
                    robot.sock.close()
    os._exit(0)
