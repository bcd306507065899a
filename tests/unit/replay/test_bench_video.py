"""``python -m benchmarks video`` (``hlvs bench video``) prints one JSON line of agreed keys."""

from __future__ import annotations

import json
import shutil
import subprocess
import sys
from pathlib import Path

import pytest


def bench_video(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-m", "benchmarks", "video", *args],
        capture_output=True, text=True, timeout=300,
    )  # fmt: skip


@pytest.mark.skipif(shutil.which("ffmpeg") is None, reason="needs ffmpeg")
def test_bench_video_prints_one_json_line() -> None:
    run = bench_video("--sim-seconds", "1", "--width", "160", "--height", "90", "--json")
    assert run.returncode == 0, run.stderr
    lines = run.stdout.strip().splitlines()
    assert len(lines) == 1
    result = json.loads(lines[0])
    assert result["bench"] == "video" and (result["width"], result["height"]) == (160, 90)
    assert result["frames"] == 26 and result["fps"] == 25.0  # 0 to 1 s in 40 ms frames
    assert result["replay"] == "recorded: 8 robots, 1 s"
    for key in ("wall_s", "ms_per_frame", "x_real_time", "render_cpu_ms_per_frame"):
        assert result[key] > 0, key
    assert result["ffmpeg_cpu_ms_per_frame"] >= 0
    assert isinstance(result["gl_renderer"], str) and result["gl_renderer"]  # what drew


def test_bench_video_rejects_bad_arguments(tmp_path: Path) -> None:
    run = bench_video("--fps", "0", "--json")
    assert run.returncode == 2 and "--fps" in run.stderr
    missing = tmp_path / "none.hlvsrec"
    run = bench_video("--replay", str(missing), "--json")
    assert run.returncode == 2 and f"{missing}: no such replay file" in run.stderr
