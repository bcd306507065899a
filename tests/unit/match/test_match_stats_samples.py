"""The engine's stats stream: which of its records are measurements."""

from __future__ import annotations

from orchestrator.engine.containers import _sample

RUNNING = {
    "read": "2026-12-03T16:54:25.329931561Z",
    "cpu_stats": {"cpu_usage": {"total_usage": 300}, "system_cpu_usage": 2000,
                  "online_cpus": 2},
    "precpu_stats": {"cpu_usage": {"total_usage": 100}, "system_cpu_usage": 1000},
    "memory_stats": {"usage": 2043904, "max_usage": 4341760},
}


def test_a_running_containers_record_is_its_peak_memory_and_cpu_share() -> None:
    sample = _sample(RUNNING)
    assert sample is not None
    assert sample.memory_bytes == 4341760
    assert sample.cpu_percent == 40.0  # 200 of 1000 ticks on 2 CPUs


def test_records_that_measured_nothing_are_skipped() -> None:
    stopped = {"read": "0001-01-01T00:00:00Z", "memory_stats": {}}
    no_cgroup = {**RUNNING, "memory_stats": {}}
    assert _sample(stopped) is None
    assert _sample(no_cgroup) is None
