"""``hlvs bench scrimmage --red-image / --blue-image``: the scrimmages it plays put those images
in the team files (a learned kick's image against the stub, say).

The benchmark runs as ``python -m hlvs bench scrimmage`` with the container engine pointed at a
socket that does not exist: the team files are written before the engine is asked for
anything, and the run then ends with the engine's error as JSON.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path


def _bench(tmp_path: Path, *args: str) -> subprocess.CompletedProcess[str]:
    env = {**os.environ, "DOCKER_HOST": f"unix://{tmp_path / 'no-engine.sock'}"}
    return subprocess.run(
        [sys.executable, "-m", "hlvs", "bench", "scrimmage", "--matches", "1",
         "--keep", str(tmp_path / "kept"), "--json", *args],
        capture_output=True, text=True, timeout=120, env=env,
    )  # fmt: skip


def test_the_images_given_play_the_teams(tmp_path: Path) -> None:
    run = _bench(tmp_path, "--red-image", "hlvs-runner/stand-kick:0123abcd",
                 "--blue-image", "hlvs-runner/stub:4567ef")
    config = tmp_path / "kept" / "match-1" / "config"
    red = json.loads((config / "team_red.json").read_text())
    blue = json.loads((config / "team_blue.json").read_text())
    assert red["image"] == "hlvs-runner/stand-kick"
    assert {p["dockerTag"] for p in red["players"].values()} == {"0123abcd"}
    assert blue["image"] == "hlvs-runner/stub"
    assert {p["dockerTag"] for p in blue["players"].values()} == {"4567ef"}
    # no engine: the run stops with the engine's error, one JSON document, not a traceback
    assert run.returncode != 0
    result = json.loads(run.stdout.strip().splitlines()[-1])
    assert result["bench"] == "scrimmage" and "error" in result
    assert "Traceback" not in run.stderr


def test_the_images_are_in_the_help() -> None:
    run = subprocess.run([sys.executable, "-m", "hlvs", "bench", "scrimmage", "--help"],
                         capture_output=True, text=True, timeout=60)  # fmt: skip
    assert run.returncode == 0
    assert "--red-image" in run.stdout and "--blue-image" in run.stdout
