"""Errors of the robot client library (all are :class:`robot.errors.RobotError`)."""

from __future__ import annotations

from robot.errors import RobotError


class RobotClientError(RobotError):
    """Root of the client library's errors."""


class ConnectFailed(RobotClientError):
    def __init__(self, *, address: str, attempts: int, reason: str) -> None:
        self.address = address
        self.attempts = attempts
        self.reason = reason
        super().__init__(f"cannot connect to {address} after {attempts} attempts: {reason}")


class HandshakeRefused(RobotClientError):
    """The simulator answered ``Refused``: this host is not allowed, or the port is taken."""

    def __init__(self, *, address: str) -> None:
        self.address = address
        super().__init__(f"{address} refused the connection (host not allowed or port in use)")


class ProtocolViolation(RobotClientError):
    def __init__(self, *, address: str, reason: str) -> None:
        self.address = address
        self.reason = reason
        super().__init__(f"{address}: {reason}")


class ConnectionClosed(RobotClientError):
    """The connection is gone: closed by the simulator, reset, or closed here (``reason``)."""

    def __init__(self, *, address: str, reason: str | None = None) -> None:
        self.address = address
        self.reason = reason
        if reason is None:
            super().__init__(f"{address} closed the connection")
        else:
            super().__init__(f"connection to {address} lost: {reason}")


class ReceiveTimeout(RobotClientError, TimeoutError):
    def __init__(self, *, address: str, timeout_s: float) -> None:
        self.address = address
        self.timeout_s = timeout_s
        super().__init__(f"no message from {address} within {timeout_s} s")


class BadAddress(RobotClientError):
    def __init__(self, *, variable: str, value: str) -> None:
        self.variable = variable
        self.value = value
        super().__init__(f"{variable}={value!r}: expected host:port, e.g. 127.0.0.1:10001")
