"""Errors of the referee package.

Tree::

    RefereeError
    ├── ProtocolError        a GameController datagram (RGme / RGrt) that does not decode
    ├── IllegalTransition    a game state change the rules do not allow
    └── ScenarioError        a scenario file that does not describe a valid case
"""

from __future__ import annotations


class RefereeError(Exception):
    """Root of every error the referee package raises."""


class ProtocolError(RefereeError):
    def __init__(self, *, peer: str, reason: str, size: int | None = None) -> None:
        self.peer = peer
        self.reason = reason
        self.size = size
        super().__init__(f"{peer}: {reason}" + (f" ({size} bytes)" if size is not None else ""))


class IllegalTransition(RefereeError):
    def __init__(self, *, current: str, requested: str) -> None:
        self.current = current
        self.requested = requested
        super().__init__(f"illegal game state transition {current} -> {requested}")


class ScenarioError(RefereeError):
    def __init__(self, *, path: str, pointer: str, reason: str) -> None:
        self.path = path
        self.pointer = pointer
        self.reason = reason
        super().__init__(f"{path}: {pointer or '/'}: {reason}")
