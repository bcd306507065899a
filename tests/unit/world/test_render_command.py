"""``hlvs render REPLAY -o match.mp4`` as the README writes it: relative paths, no ``MUJOCO_GL``
in the environment (the program picks the offscreen back end), a clear error when none works."""

from __future__ import annotations

import json
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from simulator.errors import OffscreenGLError
from simulator.gl import choose_offscreen_gl
from tests.unit.world.test_world_recorder import _record

HLVS = [sys.executable, "-m", "hlvs"]


def _environment_without_gl() -> dict[str, str]:
    env = dict(os.environ)
    env.pop("MUJOCO_GL", None)
    env.pop("PYOPENGL_PLATFORM", None)
    return env


@pytest.mark.skipif(shutil.which("ffprobe") is None, reason="needs ffmpeg")
def test_render_as_documented_from_a_relative_path(tmp_path: Path) -> None:
    folder = tmp_path / "public"
    folder.mkdir()
    _record(folder / "replay.hlvsrec", seconds=2.0, robots=2)
    done = subprocess.run(
        [*HLVS, "render", "public/replay.hlvsrec", "-o", "match.mp4",
         "--width", "160", "--height", "96", "--fps", "10"],
        cwd=tmp_path, env=_environment_without_gl(), capture_output=True, text=True, timeout=300,
    )  # fmt: skip
    assert done.returncode == 0, done.stderr
    assert "offscreen OpenGL back end: " in done.stderr
    # Not a terminal: plain progress lines, the last one at the end.
    assert re.search(r"^render match\.mp4: (\d+) of \1 frames \(100 %\)$", done.stderr, re.M)
    probe = subprocess.run(
        ["ffprobe", "-v", "error", "-show_entries",
         "stream=codec_type,codec_name,width,height:format=duration", "-of", "json",
         str(tmp_path / "match.mp4")],
        capture_output=True, text=True, check=True,
    )  # fmt: skip
    info = json.loads(probe.stdout)
    video = info["streams"][0]
    assert (video["codec_type"], video["codec_name"]) == ("video", "h264")
    assert (video["width"], video["height"]) == (160, 96)
    assert float(info["format"]["duration"]) == pytest.approx(2.0, abs=0.3)


def test_render_names_the_back_end_that_failed(tmp_path: Path) -> None:
    _record(tmp_path / "replay.hlvsrec", seconds=0.2, robots=1)
    env = _environment_without_gl() | {"MUJOCO_GL": "nonesuch"}
    done = subprocess.run(
        [*HLVS, "render", "replay.hlvsrec", "-o", "match.mp4"],
        cwd=tmp_path, env=env, capture_output=True, text=True, timeout=120,
    )  # fmt: skip
    assert done.returncode == 3, done.stderr
    assert "no offscreen OpenGL back end works" in done.stderr
    assert "MUJOCO_GL=nonesuch" in done.stderr and "unset MUJOCO_GL" in done.stderr
    assert "Traceback" not in done.stderr
    assert not (tmp_path / "match.mp4").exists()


def test_render_names_a_missing_replay_resolved(tmp_path: Path) -> None:
    done = subprocess.run(
        [*HLVS, "render", "nowhere/replay.hlvsrec", "-o", "match.mp4"],
        cwd=tmp_path, env=_environment_without_gl(), capture_output=True, text=True, timeout=60,
    )  # fmt: skip
    assert done.returncode == 2
    assert str(tmp_path / "nowhere" / "replay.hlvsrec") in done.stderr


def test_the_first_back_end_that_works_is_chosen() -> None:
    env: dict[str, str] = {}
    tried: list[str] = []

    def probe(backend: str) -> str | None:
        tried.append(backend)
        return "eglInitialize failed" if backend == "egl" else None

    assert choose_offscreen_gl(env, probe=probe) == "osmesa"
    assert tried == ["egl", "osmesa"]
    assert env == {"MUJOCO_GL": "osmesa", "PYOPENGL_PLATFORM": "osmesa"}


def test_no_back_end_lists_every_attempt() -> None:
    env: dict[str, str] = {}
    with pytest.raises(OffscreenGLError) as caught:
        choose_offscreen_gl(env, probe=lambda backend: f"{backend} library not found")
    assert caught.value.tried == (
        ("egl", "egl library not found"), ("osmesa", "osmesa library not found"),
    )
    assert "MUJOCO_GL=egl: egl library not found" in str(caught.value)
    assert "libosmesa6" in str(caught.value)
    assert "MUJOCO_GL" not in env


def test_a_back_end_set_by_the_user_is_the_only_one_tried() -> None:
    env = {"MUJOCO_GL": "osmesa"}
    tried: list[str] = []
    choose_offscreen_gl(env, probe=lambda backend: tried.append(backend) or None)
    assert tried == ["osmesa"]
