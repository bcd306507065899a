"""``python -m benchmarks sim`` prints one JSON line with the agreed keys."""

from __future__ import annotations

import json
import subprocess
import sys

import pytest


def bench_sim(*args: str) -> subprocess.CompletedProcess[str]:
    """``python -m benchmarks sim ARGS`` (what ``hlvs bench sim`` runs)."""
    return subprocess.run(
        [sys.executable, "-m", "benchmarks", "sim", *args],
        capture_output=True, text=True, timeout=300,
    )  # fmt: skip


def test_bench_sim_prints_one_json_line() -> None:
    run = bench_sim("--robots", "2", "--sim-seconds", "1", "--json")
    assert run.returncode == 0, run.stderr
    lines = run.stdout.strip().splitlines()
    assert len(lines) == 1
    result = json.loads(lines[0])
    assert result["bench"] == "sim" and result["robots"] == 2
    assert result["sim_seconds"] == pytest.approx(1.0)
    for key in ("steps_per_s", "real_time_factor", "bare_real_time_factor", "ratio"):
        assert result[key] > 0
    assert result["fallen"] == 0  # robots holding the standing posture stay up


def test_bench_sim_rejects_bad_arguments() -> None:
    run = bench_sim("--robots", "40", "--json")
    assert run.returncode == 2
    assert "--robots" in run.stderr
