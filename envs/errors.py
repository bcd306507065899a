"""Errors of the learning environments. Tree::

EnvError
├── EnvConfigError        an option with a value outside what is allowed (field, value, expected)
├── EnvStateError         an operation in the wrong phase (step before reset, after close)
├── TrainerError          a trainer operation the world cannot do (field, reason)
└── RemoteError           a remote simulator failed (address, reason)
    ├── RemoteStartFailed a container did not start or never became healthy
    └── RemoteCrashed     a remote died during an episode (address, cause)
"""

from __future__ import annotations

from collections.abc import Iterable
from difflib import get_close_matches


class EnvError(Exception):
    """Root of every error raised by :mod:`envs`."""


class EnvConfigError(EnvError):
    def __init__(
        self, *, field: str, value: object, expected: str, choices: Iterable[str] = ()
    ) -> None:
        self.field = field
        self.value = value
        self.expected = expected
        close = get_close_matches(str(value), list(choices), n=1)
        self.suggestion = close[0] if close else None
        hint = f" (did you mean {self.suggestion!r}?)" if self.suggestion else ""
        super().__init__(f"{field}: {value!r} is not valid; expected {expected}{hint}")


class EnvStateError(EnvError):
    def __init__(self, *, operation: str, reason: str) -> None:
        self.operation = operation
        self.reason = reason
        super().__init__(f"{operation}: {reason}")


class TrainerError(EnvError):
    def __init__(self, *, operation: str, reason: str) -> None:
        self.operation = operation
        self.reason = reason
        super().__init__(f"trainer {operation}: {reason}")


class RemoteError(EnvError):
    def __init__(self, *, address: str, reason: str) -> None:
        self.address = address
        self.reason = reason
        super().__init__(f"remote {address}: {reason}")


class RemoteStartFailed(RemoteError):
    pass


class RemoteCrashed(RemoteError):
    def __init__(self, *, address: str, cause: str) -> None:
        self.cause = cause
        super().__init__(address=address, reason=f"crashed: {cause}")
