"""``hlvs bench report``: the matrix in one JSON document (small sizes, no Docker kinds)."""

from __future__ import annotations

import json
import subprocess
import sys

from testkit.figures import Target
from testkit.figures import median_figures as _median


def test_report_runs_the_kinds_and_judges_medians_against_targets() -> None:
    proc = subprocess.run(
        [sys.executable, "-m", "hlvs", "bench", "report", "--only", "sim,pipelined",
         "--repeats", "2", "--robots", "2", "--sim-seconds", "0.25", "--world-seconds", "0.5",
         "--json"],
        capture_output=True, text=True, timeout=300,
    )  # fmt: skip
    assert proc.returncode == 0, proc.stderr[-2000:]
    lines = proc.stdout.strip().splitlines()
    assert len(lines) == 1  # one JSON document and nothing else on stdout
    report = json.loads(lines[0])
    assert report["bench"] == "report" and report["errors"] == 0
    assert len(report["load_average_before"]) == 3
    assert "async" not in report and "bringup" not in report
    assert report["bringup_repeats"] == 2  # as many bring-ups as --repeats unless told
    sim, pipelined = report["sim"], report["pipelined"]
    assert len(sim["runs"]) == 2 and len(pipelined["runs"]) == 2
    assert sim["target"] == {"figure": "ratio", "min": 0.95}
    assert sim["meets_target"] == (sim["median"]["ratio"] >= 0.95)
    ratio = pipelined["median"]["ratio_interleaved"]
    assert ratio > 0 and pipelined["meets_target"] == (ratio >= 0.9)
    assert 0 <= pipelined["median"]["client_wait_share"] < 1


def test_bad_kind_is_named() -> None:
    proc = subprocess.run(
        [sys.executable, "-m", "hlvs", "bench", "report", "--only", "sim,gpu"],
        capture_output=True, text=True, timeout=60,
    )  # fmt: skip
    assert proc.returncode == 2 and "--only: unknown kind(s) gpu" in proc.stderr


def test_median_skips_failed_runs_and_targets_have_a_bound() -> None:
    runs = [{"ratio": 0.9, "note": "x"}, {"error": "exit code 3"}, {"ratio": 0.7}, {"ratio": 1.0}]
    assert _median(runs) == {"ratio": 0.9}
    assert Target("bringup_s", maximum=5.0).met(4.9) and not Target("s", maximum=5.0).met(5.1)
    assert not Target("ratio", minimum=0.9).met(0.89)
