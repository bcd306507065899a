"""``hlvs bench service`` runs end to end on a small scale and reports every figure."""

from __future__ import annotations

import json
import subprocess
import sys

import pytest

pytestmark = pytest.mark.docker


def test_bench_service_small(docker_client: object) -> None:
    done = subprocess.run(
        [sys.executable, "-m", "hlvs", "bench", "service", "--pollers", "4",
         "--submitters", "2", "--duration", "3", "--json"],
        capture_output=True, text=True, timeout=300, check=False)
    result = json.loads(done.stdout.strip().splitlines()[-1])
    assert result["bench"] == "service" and result["pollers"] == 4
    for kind in ("status", "submit", "cancel"):
        assert result[kind]["errors"] == 0, result
        assert result[kind]["ok"] > 0 and result[kind]["p99_ms"] is not None
    assert result["server_cpu_ms_per_request"] > 0
    assert done.returncode == (0 if result["ok"] else 1)
