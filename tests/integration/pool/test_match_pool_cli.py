"""``hlvs scrimmage --pool slurm``: the match runs as a Slurm job on a node of the five-node
cluster, the command shows Slurm's state while it waits, the results land in the usual --out
folder and the exit code is the match's."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

pytestmark = [pytest.mark.docker, pytest.mark.root, pytest.mark.slow]


def test_scrimmage_through_the_slurm_pool(cluster: str, tmp_path: Path) -> None:
    out = tmp_path / "scrim"
    match_id = f"slurm-cli-{os.getpid()}"
    cmd = [sys.executable, "-m", "hlvs", "scrimmage", "--pool", "slurm",
           "--slurm-conf", cluster, "--half-duration", "4", "--ready-duration", "1",
           "--minimum-play", "0",
           "--wait-before-ready", "1", "--grace", "2", "--match-id", match_id,
           "--out", str(out), "--json"]
    result = subprocess.run(cmd, capture_output=True, text=True, timeout=600, check=False)
    assert result.returncode == 0, result.stdout[-2000:] + result.stderr[-3000:]
    document = json.loads(result.stdout)  # stdout is the one JSON document
    assert document["exit_code"] == 0 and document["out_dir"] == str(out)
    assert document["final_state"] == "FINISHED"
    job_id = json.loads((out / "slurm.json").read_text())["job_id"]
    assert f"Slurm job {job_id} submitted" in result.stderr
    assert f"Slurm job {job_id} running: on n" in result.stderr  # the node it runs on
    assert json.loads((out / "report.json").read_text())["status"] == "success"
    assert json.loads((out / "results.json").read_text())["match_id"] == match_id
    sacct = subprocess.run(["sacct", "-n", "-X", "-P", "-j", job_id, "-o", "State,NodeList"],
                           capture_output=True, text=True, check=True,
                           env={**os.environ, "SLURM_CONF": cluster}).stdout
    state, node = sacct.strip().splitlines()[0].split("|")
    assert state == "COMPLETED" and node.startswith("n"), sacct
