"""``python -m simulator bench sim`` prints one JSON line with the agreed keys."""

from __future__ import annotations

import json

import pytest

from simulator.bench_sim import main


def test_bench_sim_prints_one_json_line(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["--robots", "2", "--sim-seconds", "1", "--json"]) == 0
    lines = capsys.readouterr().out.strip().splitlines()
    assert len(lines) == 1
    result = json.loads(lines[0])
    assert result["bench"] == "sim" and result["robots"] == 2
    assert result["sim_seconds"] == pytest.approx(1.0)
    for key in ("steps_per_s", "real_time_factor", "bare_real_time_factor", "ratio"):
        assert result[key] > 0
    assert result["fallen"] == 0  # robots holding the standing posture stay up


def test_bench_sim_rejects_bad_arguments(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["--robots", "40", "--json"]) == 2
    assert "--robots" in capsys.readouterr().err
