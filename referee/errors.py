"""Errors of the referee package.

Tree::

    RefereeError
    ├── IllegalTransition    a game state change the rules do not allow
    └── ScenarioError        a scenario file that does not describe a valid case

A GameController datagram that does not decode raises :class:`contracts.errors.ProtocolError`.
"""

from __future__ import annotations

from contracts import ProtocolError


class RefereeError(Exception):
    """Root of every error the referee package raises."""


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


__all__ = ["IllegalTransition", "ProtocolError", "RefereeError", "ScenarioError"]
