"""Errors of the robot-side package.

Tree::

    RobotError
    ├── UnknownModelError    a robot model name we do not ship (lists the known ones)
    ├── RobotClientError     robot API / GameController client errors (robot.client.errors)
    └── StubError            the stub robot controller's errors (robot.stub.errors)
"""

from __future__ import annotations


class RobotError(Exception):
    """Root of every error the robot package raises."""


class UnknownModelError(RobotError):
    def __init__(self, *, name: str, known: list[str]) -> None:
        self.name = name
        self.known = sorted(known)
        super().__init__(f"unknown robot model {name!r}; known models: {', '.join(self.known)}")
