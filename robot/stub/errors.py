"""Errors of the stub robot controller (part of the robot package's error tree)."""

from __future__ import annotations

from robot.errors import RobotError


class StubError(RobotError):
    """Root of the stub controller's errors."""


class StubConfigError(StubError):
    """A bad command line or ``ROBOCUP_*`` variable."""

    def __init__(self, *, field: str, value: str, expected: str) -> None:
        self.field = field
        self.value = value
        self.expected = expected
        super().__init__(f"stub robot: {field}: got {value!r}, expected {expected}")


class StubConnectionError(StubError):
    """The simulator did not accept the robot within the retry budget."""

    def __init__(self, *, address: str, attempts: int, reason: str) -> None:
        self.address = address
        self.attempts = attempts
        self.reason = reason
        super().__init__(
            f"stub robot: cannot connect to {address} after {attempts} attempts: {reason}"
        )
