"""What one robot API client may cost the step: bounds on its requests.

A robot's requests are read, decoded and applied by the simulator's own threads, so a client
that floods its port (4 MB ``ActuatorRequests`` without pause) would slow every robot of both
teams. Three bounds keep its cost to itself:

- one request is at most :data:`MAX_REQUEST_BYTES` (far above any real ``ActuatorRequests``);
  a larger one is dropped without being decoded;
- each client has a byte and a message budget per second of real time (token buckets:
  :data:`RATE_BYTES_S` with a burst of :data:`BURST_BYTES`, :data:`RATE_MESSAGES_S` with a burst
  of :data:`BURST_MESSAGES`); requests beyond them are dropped without being decoded;
- one read of a client takes at most :data:`READ_PER_CALL_BYTES` from its socket; the rest
  waits in the kernel for the next poll, so one client never holds the loop.

Dropped requests are counted per robot and reason (``dropped_in`` in the API statistics of
``sim_result.json``); the connection stays open.
"""

from __future__ import annotations

MAX_REQUEST_BYTES = 256 * 1024
RATE_BYTES_S = 8 * 1024 * 1024
BURST_BYTES = 2 * 1024 * 1024
RATE_MESSAGES_S = 20_000
BURST_MESSAGES = 2000
READ_PER_CALL_BYTES = 512 * 1024


class TokenBucket:
    """``rate`` per second, up to ``burst`` saved; :meth:`take` spends ``amount`` if there."""

    __slots__ = ("_burst", "_level", "_rate", "_updated")

    def __init__(self, *, rate: float, burst: float, now: float) -> None:
        self._rate = rate
        self._burst = burst
        self._level = burst
        self._updated = now

    def take(self, amount: float, now: float) -> bool:
        if amount <= self._level:  # the usual case: no refill needed
            self._level -= amount
            return True
        elapsed = now - self._updated
        self._updated = now
        if elapsed > 0:
            self._level = min(self._burst, self._level + elapsed * self._rate)
        if amount <= self._level:
            self._level -= amount
            return True
        return False


class RequestBounds:
    """The byte and message budgets of one client; :meth:`admit` says whether a request of
    ``size`` bytes may be decoded, else the reason it is dropped."""

    __slots__ = ("_bytes", "_messages", "max_bytes")

    def __init__(self, now: float, *, max_bytes: int = MAX_REQUEST_BYTES,
                 rate_bytes_s: float = RATE_BYTES_S, burst_bytes: float = BURST_BYTES,
                 rate_messages_s: float = RATE_MESSAGES_S,
                 burst_messages: float = BURST_MESSAGES) -> None:
        self.max_bytes = max_bytes
        self._bytes = TokenBucket(rate=rate_bytes_s, burst=burst_bytes, now=now)
        self._messages = TokenBucket(rate=rate_messages_s, burst=burst_messages, now=now)

    def admit(self, size: int, now: float) -> str | None:
        """None when the request may be decoded, else why it is dropped ("size", "rate")."""
        if size > self.max_bytes:
            return "size"
        if not self._messages.take(1, now):
            return "rate"
        if not self._bytes.take(size, now):
            return "rate"
        return None


__all__ = [
    "BURST_BYTES", "BURST_MESSAGES", "MAX_REQUEST_BYTES", "RATE_BYTES_S", "RATE_MESSAGES_S",
    "READ_PER_CALL_BYTES", "RequestBounds", "TokenBucket",
]
