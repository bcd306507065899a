"""Robot API client: connect, enable sensors, send actuator requests, receive measurements."""

from __future__ import annotations

import math
import os
import select
import socket
import struct
import threading
import time
from collections.abc import Iterator, Mapping
from types import TracebackType

from google.protobuf.message import DecodeError

from contracts.robot_api import messages_pb2 as pb
from robot.client.errors import (
    BadAddress,
    ConnectFailed,
    ConnectionClosed,
    HandshakeRefused,
    ProtocolViolation,
    ReceiveTimeout,
)

_HEADER = struct.Struct(">I")
MAX_MESSAGE_BYTES = 1920 * 1080 * 3 + 1000
ENV_ADDRESS = "ROBOCUP_SIMULATOR_ADDR"
_FD_SETSIZE = 1024


class RobotClient:
    """A blocking client for one robot, like the league's reference client.

    Example::

        with RobotClient("127.0.0.1", 10001) as robot:
            robot.enable_many({"NeckS": 8, "Accelerometer": 8, "Gyro": 8})
            for measurement in robot:
                robot.set_positions({"Neck": 0.5})
    """

    def __init__(
        self, host: str, port: int, *, retries: int = 20, retry_interval_s: float = 1.0,
        connect_timeout_s: float = 5.0,
    ) -> None:
        self.host = host
        self.port = port
        self.retries = max(1, retries)
        self.retry_interval_s = retry_interval_s
        # how long one connect may wait (an address whose host is gone answers nothing)
        self.connect_timeout_s = connect_timeout_s
        self._sock: socket.socket | None = None
        self._buffer = bytearray()
        # one frame at a time: ``sendall`` may take several writes and lets other threads run
        # between them, so two threads sending at once would interleave their bytes
        self._send_lock = threading.Lock()

    @property
    def address(self) -> str:
        return f"{self.host}:{self.port}"

    @classmethod
    def from_env(cls, *, retries: int = 20, retry_interval_s: float = 1.0) -> RobotClient:
        """Build from ``ROBOCUP_SIMULATOR_ADDR`` (``host:port``)."""
        value = os.environ.get(ENV_ADDRESS, "")
        host, sep, port = value.rpartition(":")
        if not sep or not host or not port.isdigit():
            raise BadAddress(variable=ENV_ADDRESS, value=value)
        return cls(host, int(port), retries=retries, retry_interval_s=retry_interval_s)

    # --- connection -------------------------------------------------------------------------

    def connect(self) -> RobotClient:
        """Connect (retrying) and complete the handshake.

        Raises:
            HandshakeRefused: the simulator answered ``Refused``.
            ConnectFailed: no connection after ``retries`` attempts.
        """
        reason = ""
        for attempt in range(1, self.retries + 1):
            try:
                sock = socket.create_connection((self.host, self.port),
                                                timeout=self.connect_timeout_s)
            except OSError as exc:
                reason = str(exc)
                if attempt < self.retries:
                    time.sleep(self.retry_interval_s)
                continue
            try:
                greeting = _recv_exact(sock, 8, self.address)
            except (OSError, ConnectionClosed) as exc:
                sock.close()
                reason = f"handshake failed: {exc}"
                if attempt < self.retries:
                    time.sleep(self.retry_interval_s)
                continue
            if greeting == b"Refused\0":
                sock.close()
                raise HandshakeRefused(address=self.address)
            if greeting != b"Welcome\0":
                sock.close()
                raise ProtocolViolation(address=self.address, reason=f"bad greeting {greeting!r}")
            sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
            sock.settimeout(None)
            self._sock = sock
            return self
        raise ConnectFailed(address=self.address, attempts=self.retries, reason=reason)

    def close(self) -> None:
        if self._sock is not None:
            self._sock.close()
            self._sock = None

    def __enter__(self) -> RobotClient:
        if self._sock is None:
            self.connect()
        return self

    def __exit__(
        self, kind: type[BaseException] | None, exc: BaseException | None, tb: TracebackType | None
    ) -> None:
        self.close()

    def _socket(self) -> socket.socket:
        if self._sock is None:
            raise ConnectionClosed(address=self.address, reason="closed by this client")
        return self._sock

    # --- sending ----------------------------------------------------------------------------

    def send(self, request: pb.ActuatorRequests) -> None:
        payload = request.SerializeToString()
        try:
            with self._send_lock:
                self._socket().sendall(_HEADER.pack(len(payload)) + payload)
        except OSError as exc:
            self.close()
            raise ConnectionClosed(address=self.address, reason=f"send failed: {exc}") from exc

    def enable(self, sensor_name: str, period_ms: int) -> None:
        """Enable a sensor every ``period_ms`` (a multiple of 8; 0 disables it)."""
        self.enable_many({sensor_name: period_ms})

    def enable_many(self, periods_ms: Mapping[str, int]) -> None:
        request = pb.ActuatorRequests()
        for name, period in periods_ms.items():
            request.sensor_time_steps.add(name=name, timeStep=period)
        self.send(request)

    def set_pids(self, gains: Mapping[str, tuple[float, float, float]]) -> None:
        """Webots' ``setControlPID`` per motor: ``{name: (P, I, D)}``."""
        request = pb.ActuatorRequests()
        for name, (p, i, d) in gains.items():
            request.motor_pids.add(name=name, PID=pb.Vector3(X=p, Y=i, Z=d))
        self.send(request)

    def set_positions(self, positions_rad: Mapping[str, float]) -> None:
        request = pb.ActuatorRequests()
        for name, position in positions_rad.items():
            request.motor_positions.add(name=name, position=position)
        self.send(request)

    # --- receiving --------------------------------------------------------------------------

    def receive(self, timeout: float | None = None) -> pb.SensorMeasurements:
        """The next measurement (one per 8 ms simulation step).

        Raises:
            ReceiveTimeout: nothing complete arrived within ``timeout`` seconds.
            ConnectionClosed: the simulator closed the connection.
            ProtocolViolation: an out-of-range length or an undecodable message.
        """
        sock = self._socket()
        deadline = None if timeout is None else time.monotonic() + timeout
        while True:
            payload = self._take_frame()
            if payload is not None:
                msg = pb.SensorMeasurements()
                try:
                    msg.ParseFromString(payload)
                except DecodeError as exc:
                    raise ProtocolViolation(address=self.address, reason=str(exc)) from exc
                return msg
            if deadline is not None:
                remaining = deadline - time.monotonic()
                if remaining <= 0 or not _readable(sock, remaining):
                    raise ReceiveTimeout(address=self.address, timeout_s=timeout or 0.0)
            try:
                data = sock.recv(1 << 20)
            except OSError as exc:
                self.close()
                raise ConnectionClosed(
                    address=self.address, reason=f"receive failed: {exc}"
                ) from exc
            if not data:
                self.close()
                raise ConnectionClosed(address=self.address)
            self._buffer += data

    def _take_frame(self) -> bytes | None:
        buffer = self._buffer
        if len(buffer) < 4:
            return None
        (length,) = _HEADER.unpack_from(buffer)
        if length == 0 or length > MAX_MESSAGE_BYTES:
            self.close()
            raise ProtocolViolation(address=self.address, reason=f"out of sync: length {length}")
        if len(buffer) < 4 + length:
            return None
        payload = bytes(buffer[4 : 4 + length])
        del buffer[: 4 + length]
        return payload

    def __iter__(self) -> Iterator[pb.SensorMeasurements]:
        """Measurements until the simulator closes the connection."""
        while True:
            try:
                yield self.receive()
            except ConnectionClosed:
                return


def _readable(sock: socket.socket, timeout_s: float) -> bool:
    """Whether ``sock`` has data (or its end) within ``timeout_s``. The wait is a poll, not a
    socket timeout, so a thread sending on the same client never inherits a receive's
    timeout (a blocked ``sendall`` with a 0.5 ms timeout would fail and drop the connection).
    """
    try:
        if sock.fileno() < _FD_SETSIZE:  # select waits in microseconds, poll in milliseconds
            return bool(select.select([sock], [], [], timeout_s)[0])
        poller = select.poll()
        poller.register(sock, select.POLLIN)
        return bool(poller.poll(math.ceil(timeout_s * 1000)))
    except (OSError, ValueError):
        return True  # closed under us: recv reports it


def _recv_exact(sock: socket.socket, size: int, address: str) -> bytes:
    data = b""
    while len(data) < size:
        chunk = sock.recv(size - len(data))
        if not chunk:
            raise ConnectionClosed(address=address)
        data += chunk
    return data
