"""Network quota of the robot API (HLVS ``team_network_quota``).

Each robot may receive ``team_quota / players_in_team`` MB/s (2^20 bytes) measured over a 1 s
sliding window of real time. A measurement that would exceed it is replaced by an
``ERROR_MESSAGE "<quota> MB/s quota exceeded."`` that keeps ``time`` and ``real_time``.
"""

from __future__ import annotations

from collections import deque


class NetworkQuota:
    """Sliding-window byte budget of one robot."""

    __slots__ = ("quota_mb_s", "window_ms", "_history", "_total", "_limit")

    def __init__(self, *, quota_mb_s: float, window_s: float = 1.0) -> None:
        self.quota_mb_s = quota_mb_s
        self.window_ms = window_s * 1000.0
        self._history: deque[tuple[int, int]] = deque()
        self._total = 0  # bytes in the history (may hold entries older than the window)
        self._limit = self.limit_bytes

    @property
    def limit_bytes(self) -> float:
        return self.quota_mb_s * (self.window_ms / 1000.0) * 2**20

    @property
    def error_text(self) -> str:
        return f"{self.quota_mb_s:f} MB/s quota exceeded."

    def _expire(self, now_ms: int) -> None:
        history = self._history
        while history and now_ms - history[0][0] >= self.window_ms:
            self._total -= history.popleft()[1]

    def allows(self, size: int, now_ms: int) -> bool:
        """Whether a message of ``size`` bytes sent at ``now_ms`` (unix ms) fits the budget."""
        if size + self._total <= self._limit:  # fits even counting expired entries
            return True
        self._expire(now_ms)
        return size + self._total <= self._limit

    def admit(self, size: int, now_ms: int) -> bool:
        """:meth:`allows`, and :meth:`record` the message when it does (one call per message
        on the usual path)."""
        if not self.allows(size, now_ms):
            return False
        self.record(size, now_ms)
        return True

    def record(self, size: int, now_ms: int) -> None:
        history = self._history
        history.append((now_ms, size))
        self._total += size
        if len(history) > 1024:  # keep the history short when nothing needed expiring
            self._expire(now_ms)
