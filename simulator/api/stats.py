"""Per-robot statistics of the robot API, reported in ``sim_result.json``."""

from __future__ import annotations

from array import array
from dataclasses import dataclass, field

from contracts import RobotApiStats


def percentile(sorted_values: list[float], q: float) -> float:
    """Nearest-rank percentile of already sorted values (q in 0..100)."""
    if not sorted_values:
        return float("nan")
    rank = max(0, min(len(sorted_values) - 1, round(q / 100.0 * (len(sorted_values) - 1))))
    return sorted_values[rank]


@dataclass(slots=True)
class RobotStats:
    """Counters of one robot over the whole match (all its connections)."""

    connects: list[float] = field(default_factory=list)  # unix s
    disconnects: list[float] = field(default_factory=list)
    disconnect_reasons: list[str] = field(default_factory=list)
    refused: int = 0
    messages_in: int = 0
    bytes_in: int = 0
    messages_out: int = 0
    bytes_out: int = 0
    dropped_out: int = 0
    quota_errors: int = 0
    bad_frames: int = 0
    decode_errors: int = 0
    missed_deadlines: int = 0
    slow_periods: int = 0
    warnings_sent: int = 0
    round_trip_s: array[float] = field(default_factory=lambda: array("d"))
    # the client's round trip seen from the server: a request's first byte received to the
    # next measurement's last byte written (simulator.api.connection.Connection._written)
    reply_s: array[float] = field(default_factory=lambda: array("d"))
    # requests dropped undecoded, by reason ("size": over the request limit; see
    # simulator.api.bounds: requests beyond the client's budget are not dropped but left unread)
    dropped_in: dict[str, int] = field(default_factory=dict)
    dropped_in_bytes: int = 0

    def drop_in(self, reason: str, size: int) -> None:
        self.dropped_in[reason] = self.dropped_in.get(reason, 0) + 1
        self.dropped_in_bytes += size

    def to_dict(self) -> RobotApiStats:
        latencies = sorted(self.round_trip_s)
        ms = _quantiles_ms(latencies)
        replies = sorted(self.reply_s)
        return {
            "connects": [round(t, 3) for t in self.connects],
            "disconnects": [round(t, 3) for t in self.disconnects],
            "disconnect_reasons": list(self.disconnect_reasons),
            "refused_connections": self.refused,
            "messages_in": self.messages_in,
            "bytes_in": self.bytes_in,
            "messages_out": self.messages_out,
            "bytes_out": self.bytes_out,
            "dropped_out": self.dropped_out,
            "dropped_in": dict(self.dropped_in),
            "dropped_in_bytes": self.dropped_in_bytes,
            "quota_errors": self.quota_errors,
            "bad_frames": self.bad_frames,
            "decode_errors": self.decode_errors,
            "missed_deadlines": self.missed_deadlines,
            "slow_periods": self.slow_periods,
            "warnings_sent": self.warnings_sent,
            "round_trip_ms": ms,
            "round_trip_samples": len(latencies),
            "reply_ms": _quantiles_ms(replies),
            "reply_samples": len(replies),
        }


def _quantiles_ms(ordered: list[float]) -> dict[str, float | None]:
    """p50, p90, p99 and max of sorted seconds, in milliseconds (None without samples)."""
    ms: dict[str, float | None] = {
        f"p{q}": round(percentile(ordered, q) * 1000.0, 3) if ordered else None
        for q in (50, 90, 99)
    }
    ms["max"] = round(ordered[-1] * 1000.0, 3) if ordered else None
    return ms
