"""Wall-clock access for the referee, injected so tests can drive it.

The game clock itself runs on simulated time (fed by snapshots); only the league's real-time
waits (before the first READY, before the second half) and the STATUS lines use a :class:`Clock`.
"""

from __future__ import annotations

import time
from typing import Protocol


class Clock(Protocol):
    def monotonic(self) -> float:
        """Seconds from an arbitrary origin; never goes backwards."""
        ...


class SystemClock:
    def monotonic(self) -> float:
        return time.monotonic()


class FakeClock:
    """A clock that moves only when told to (or by ``auto_advance_s`` on every read)."""

    def __init__(self, *, start_s: float = 0.0, auto_advance_s: float = 0.0) -> None:
        self._now_s = start_s
        self._auto_advance_s = auto_advance_s

    def monotonic(self) -> float:
        now = self._now_s
        self._now_s += self._auto_advance_s
        return now

    def advance(self, seconds: float) -> None:
        if seconds < 0:
            raise ValueError("a clock cannot go backwards")
        self._now_s += seconds
