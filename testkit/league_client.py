"""A robot API client written like the league's own ``test_client``
(``controllers/player/robot_client.cpp`` of hlvs_webots): blocking socket, no ``TCP_NODELAY``,
and each request sent in two writes, the 4-byte length (``robot_client.cpp:171``) and then the
body (``:178-179``, a ``FileOutputStream`` over the socket). With Nagle's algorithm the body
waits until the length is acknowledged, so a server that delays its ACKs stalls every request
(40 ms on Linux).

It times what it can see of each exchange: ``answer_s``, from a measurement's arrival to the
return of its answer's last write (the part of the server's round trip spent here), and
``round_trip_s``, from that return to the arrival of the next measurement (what the league's
client waits for in ``RobotClient::receive``).
"""

from __future__ import annotations

import socket
import struct
import time
from collections.abc import Callable

from contracts.robot_api import messages_pb2 as pb

HEADER = struct.Struct(">I")


class LeagueStyleClient:
    """One robot's client; :meth:`connect`, then :meth:`exchange` per measurement."""

    def __init__(
        self, host: str, port: int, *, timeout_s: float = 10.0, split_writes: bool = True
    ) -> None:
        """``split_writes`` False: each request in one write (as clients that frame first)."""
        self.split_writes = split_writes
        self.host = host
        self.port = port
        self.timeout_s = timeout_s
        self.sock: socket.socket | None = None
        self.answer_s: list[float] = []
        self.round_trip_s: list[float] = []
        self._buffer = bytearray()
        self._answered_at: float | None = None

    def connect(self) -> LeagueStyleClient:
        sock = socket.create_connection((self.host, self.port), timeout=self.timeout_s)
        greeting = self._exactly(sock, 8)
        if greeting != b"Welcome\0":
            sock.close()
            raise ConnectionError(f"{self.host}:{self.port} answered {greeting!r}")
        self.sock = sock
        return self

    def close(self) -> None:
        if self.sock is not None:
            self.sock.close()
            self.sock = None

    def __enter__(self) -> LeagueStyleClient:
        return self.connect() if self.sock is None else self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def send(self, body: bytes) -> None:
        """One request as the league's client sends it: the length, then the body."""
        assert self.sock is not None
        if not self.split_writes:
            self.sock.sendall(HEADER.pack(len(body)) + body)
            return
        self.sock.send(HEADER.pack(len(body)))
        self.sock.sendall(body)

    def receive(self) -> bytes:
        """The next measurement's payload (not decoded)."""
        assert self.sock is not None
        (length,) = HEADER.unpack(self._exactly(self.sock, 4))
        payload = self._exactly(self.sock, length)
        if self._answered_at is not None:
            self.round_trip_s.append(time.monotonic() - self._answered_at)
            self._answered_at = None
        return payload

    def exchange(self, body: bytes, think: Callable[[], None] | None = None) -> bytes:
        """Receive a measurement, ``think``, answer it with ``body``; the measurement."""
        payload = self.receive()
        arrived = time.monotonic()
        if think is not None:
            think()
        self.send(body)
        self._answered_at = time.monotonic()
        self.answer_s.append(self._answered_at - arrived)
        return payload

    def _exactly(self, sock: socket.socket, count: int) -> bytes:
        buffer = self._buffer
        while len(buffer) < count:
            chunk = sock.recv(max(65536, count - len(buffer)))
            if not chunk:
                raise ConnectionError(f"{self.host}:{self.port} closed the connection")
            buffer += chunk
        data = bytes(buffer[:count])
        del buffer[:count]
        return data


def neck_request(position: float, *, enable: bool = False) -> bytes:
    """The league's test_client's request (``test_client.cpp:78-93``): the neck's position,
    and with ``enable`` the ``NeckS`` sensor at 8 ms."""
    request = pb.ActuatorRequests()
    if enable:
        request.sensor_time_steps.add(name="NeckS", timeStep=8)
    request.motor_positions.add(name="Neck", position=position)
    body: bytes = request.SerializeToString()
    return body


__all__ = ["LeagueStyleClient", "neck_request"]
