"""api_stats.jsonl: per-robot traffic samples once a wall second, round trips per interval."""

from __future__ import annotations

from pathlib import Path

from simulator.api.stats import RobotStats
from simulator.traffic import TrafficLog, read_stats


class _Server:
    def __init__(self) -> None:
        self.red = RobotStats()
        self.blue = RobotStats()

    def traffic(self) -> dict[str, tuple[bool, RobotStats]]:
        return {"red_1": (True, self.red), "blue_1": (False, self.blue)}


def test_samples_are_written_once_a_period_with_interval_round_trips(tmp_path: Path) -> None:
    server = _Server()
    path = tmp_path / "api_stats.jsonl"
    log = TrafficLog(server, path=path, period_s=1.0)
    server.red.bytes_in, server.red.bytes_out = 100, 2000
    server.red.round_trip_s.extend([0.002, 0.004])
    log.sample(now_s=10.0, sim_time_ms=0, real_time_factor=0.0)
    server.red.round_trip_s.append(0.010)
    log.sample(now_s=10.5, sim_time_ms=500, real_time_factor=1.0)  # not due: skipped
    server.red.bytes_in = 300
    log.sample(now_s=11.0, sim_time_ms=1000, real_time_factor=1.25)
    log.sample(now_s=12.1, sim_time_ms=2100, real_time_factor=1.0)
    log.close()
    samples = read_stats(path)
    assert [s["real_time_s"] for s in samples] == [0.0, 1.0, 2.1]
    assert [s["real_time_factor"] for s in samples] == [0.0, 1.25, 1.0]
    assert [s["robots"]["red_1"]["round_trip_ms"] for s in samples] == [3.0, 10.0, None]
    assert samples[1]["robots"]["red_1"]["bytes_in"] == 300
    assert samples[0]["robots"]["blue_1"] == {
        "connected": False, "bytes_in": 0, "bytes_out": 0, "messages_in": 0,
        "messages_out": 0, "round_trip_ms": None,
    }  # fmt: skip
    assert log.latest == samples[-1]
