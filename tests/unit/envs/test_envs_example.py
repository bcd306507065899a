"""The learning example runs and reports its kick distances (a short search)."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[3]


def test_learn_kick_example_runs_and_reports() -> None:
    out = subprocess.run(
        [sys.executable, str(ROOT / "examples" / "learn_kick.py"), "--seed", "1",
         "--iterations", "1", "--population", "3", "--episode-s", "2.5"],
        capture_output=True, text=True, timeout=300, check=True, cwd=ROOT,
    )  # fmt: skip
    report = json.loads(out.stdout.strip().splitlines()[-1])
    assert report["seed"] == 1 and report["episodes"] == 5
    assert report["best_kick_m"] >= report["initial_kick_m"] > 0.0
