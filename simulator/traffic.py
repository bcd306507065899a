"""Per-robot API traffic and the real-time factor over a match: ``api_stats.jsonl``.

About once a wall-clock second :class:`TrafficLog` takes a sample from the robot API server's
counters and writes it as one JSON line::

    {"real_time_s", "sim_time_ms", "real_time_factor",
     "robots": {"red-1": {"connected", "bytes_in", "bytes_out", "messages_in", "messages_out",
                          "round_trip_ms"}}}

Byte and message counts are totals since the start; ``round_trip_ms`` is the mean round trip of
the replies in this sample's interval (None when there were none). The latest sample also goes
into the telemetry state (connection health for the live view). It is kept apart from the
replay, which holds nothing measured on the wall clock.
"""

from __future__ import annotations

import contextlib
import json
import logging
from pathlib import Path
from typing import IO, Protocol, cast

from contracts import RobotTraffic, TrafficSample, files
from simulator.api.stats import RobotStats

log = logging.getLogger(__name__)

STATS_FILE = files.API_STATS
SAMPLE_PERIOD_S = 1.0


class TrafficSource(Protocol):
    def traffic(self) -> dict[str, tuple[bool, RobotStats]]: ...


class TrafficLog:
    """Samples ``source`` every ``period_s`` (wall); writes to ``path`` when one is given."""

    def __init__(
        self, source: TrafficSource, *, path: Path | None, period_s: float = SAMPLE_PERIOD_S
    ) -> None:
        self._source = source
        self._period_s = period_s
        self._next_s: float | None = None
        self._started_s: float | None = None
        self._seen: dict[str, int] = {}
        self.latest: TrafficSample | None = None
        self._out: IO[str] | None = path.open("w", encoding="utf-8") if path else None

    def sample(self, *, now_s: float, sim_time_ms: int, real_time_factor: float) -> None:
        """Take a sample if one is due at wall time ``now_s`` (monotonic seconds)."""
        if self._started_s is None:
            self._started_s = now_s
        if self._next_s is not None and now_s < self._next_s:
            return
        self._next_s = now_s + self._period_s
        robots: dict[str, RobotTraffic] = {}
        for key, (connected, stats) in sorted(self._source.traffic().items()):
            seen = self._seen.get(key, 0)
            fresh = stats.round_trip_s[seen:]
            self._seen[key] = seen + len(fresh)
            robots[key] = {
                "connected": connected,
                "bytes_in": stats.bytes_in,
                "bytes_out": stats.bytes_out,
                "messages_in": stats.messages_in,
                "messages_out": stats.messages_out,
                "round_trip_ms": round(sum(fresh) / len(fresh) * 1000.0, 3) if fresh else None,
            }
        self.latest = {
            "real_time_s": round(now_s - self._started_s, 3),
            "sim_time_ms": sim_time_ms,
            "real_time_factor": round(real_time_factor, 3),
            "robots": robots,
        }
        if self._out is not None:
            try:
                self._out.write(json.dumps(self.latest, sort_keys=True) + "\n")
                self._out.flush()
            except OSError as exc:  # the disk full: the statistics stop, the match goes on
                log.error("%s cut at %d ms of simulated time: %s", self._out.name, sim_time_ms,
                          exc.strerror or exc)
                with contextlib.suppress(OSError):
                    self._out.close()
                self._out = None

    def close(self) -> None:
        if self._out is not None:
            with contextlib.suppress(OSError):
                self._out.close()
            self._out = None


def read_stats(path: Path) -> list[TrafficSample]:
    """The samples of an ``api_stats.jsonl`` file (lines that are not JSON objects skipped)."""
    samples: list[TrafficSample] = []
    for line in path.read_text(encoding="utf-8").splitlines():
        try:
            value = json.loads(line)
        except ValueError:
            continue
        if isinstance(value, dict):
            samples.append(cast("TrafficSample", value))  # written by TrafficLog
    return samples
