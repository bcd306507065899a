"""What one robot API client may cost the step: a budget charged before any per-frame work.

A robot's requests are read, framed, decoded and applied by the simulator's own threads, so a
client that floods its port (4 MB ``ActuatorRequests`` without pause, or small valid ones by the
hundred thousand) would slow every robot of both teams. Each client has a :class:`ReadBudget`,
charged in the reader itself, before the frames are cut out:

- every byte received costs :data:`BYTE_COST` (charged as it is received) and every frame
  :data:`FRAME_COST` (charged as it is cut out of the stream: the reader cuts no more frames
  than the budget pays for, the rest stays buffered);
- the budget refills by :data:`RATE_S` per second of real time and by
  :data:`PER_MEASUREMENT` for each measurement sent to the client (so a lockstep client, which
  answers each measurement once, never runs dry however fast the world steps), up to
  :data:`BURST`;
- a client whose budget is spent is not read at all until it refills: its socket is not even
  watched, so its requests wait in the kernel and TCP stops the sender. It is marked slow as a
  robot too slow for lockstep is (logged, ``slow_periods``): lockstep does not wait for it
  until it is read again and has answered;
- one request is at most :data:`MAX_REQUEST_BYTES` (far above any real ``ActuatorRequests``);
  a larger one is dropped without being decoded, counted (``dropped_in`` ``size``) and told to
  the client in its next measurement;
- one read of a client takes at most :data:`READ_PER_CALL_BYTES` from its socket; the rest
  waits in the kernel for the next poll, so one client never holds the loop.

An honest client (one request per measurement, a few hundred bytes each) costs 1.1 units of a
refill of 2 per measurement and never meets the bound.
"""

from __future__ import annotations

MAX_REQUEST_BYTES = 256 * 1024
READ_PER_CALL_BYTES = 512 * 1024
FRAME_COST = 1.0
BYTE_COST = 1.0 / 4096  # a 4 KiB request costs a second frame; 4 MiB cost 1024
RATE_S = 1000.0
PER_MEASUREMENT = 2.0
BURST = 200.0


class ReadBudget:
    """One client's budget (units of :data:`FRAME_COST`): :meth:`refill` before a read, then
    the reader spends ``level`` (it may go below 0: the bytes of the last receive)."""

    __slots__ = ("level", "rate", "burst", "per_measurement", "_updated", "_credited")

    def __init__(self, now: float, *, rate: float = RATE_S, burst: float = BURST,
                 per_measurement: float = PER_MEASUREMENT) -> None:  # fmt: skip
        self.rate = rate
        self.burst = burst
        self.per_measurement = per_measurement
        self.level = burst
        self._updated = now
        self._credited = 0

    def refill(self, now: float, measurements: int) -> float:
        """The level after the real time since the last call and the measurements sent since
        (``measurements``: the count sent so far)."""
        level = self.level
        if level < self.burst:
            level += (now - self._updated) * self.rate
            level += (measurements - self._credited) * self.per_measurement
            self.level = level = min(level, self.burst)
        self._updated = now
        self._credited = measurements
        return level


__all__ = [
    "BURST", "BYTE_COST", "FRAME_COST", "MAX_REQUEST_BYTES", "PER_MEASUREMENT", "RATE_S",
    "READ_PER_CALL_BYTES", "ReadBudget",
]
