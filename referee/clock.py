"""Wall-clock access for the referee, injected so tests can drive it.

The game clock itself runs on simulated time (fed by snapshots); only the league's real-time
waits (before the first READY, before the second half) and the STATUS lines use a :class:`Clock`.
"""

from __future__ import annotations

import time
from typing import Generic, Protocol, TypeVar

Then = TypeVar("Then")


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


class WallClockWait(Generic[Then]):
    """At most one pending wait of some seconds of wall-clock time, and what comes after it.
    Each of :meth:`start` and :meth:`over` reads the clock once."""

    def __init__(self, clock: Clock) -> None:
        self._clock = clock
        self._until_s: float | None = None
        self._then: Then | None = None

    @property
    def pending(self) -> bool:
        return self._until_s is not None

    def start(self, seconds: float, then: Then) -> None:
        self._until_s = self._clock.monotonic() + seconds
        self._then = then

    def over(self) -> bool:
        """The pending wait is over (its time has come)."""
        assert self._until_s is not None
        return self._clock.monotonic() >= self._until_s

    def take(self) -> Then | None:
        """What comes after the wait; the wait ends."""
        then = self._then
        self.cancel()
        return then

    def cancel(self) -> None:
        self._until_s = None
        self._then = None
