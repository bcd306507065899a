"""How many processes render a match's robot cameras: one per CPU (at most four) on the CPU
renderer and on a GPU, a thread on a single CPU or without an offscreen back end."""

from __future__ import annotations

import pytest

from contracts import MAX_RENDER_PROCESSES
from simulator.api import world_cameras
from simulator.api.world_cameras import render_processes


@pytest.mark.parametrize(
    ("gl", "cpus", "expected"),
    [
        ("osmesa", 2, 2),
        ("osmesa", 3, 3),
        ("osmesa", 16, MAX_RENDER_PROCESSES),
        ("osmesa", 1, 0),  # a simulator pinned to one CPU: the thread
        ("egl", 16, MAX_RENDER_PROCESSES),  # on an H200: 2.0-2.1 x real time against 1.2-1.3
        ("egl", 2, 2),
        ("egl", 1, 0),
        ("", 16, 0),  # no offscreen back end chosen: the thread (as before)
    ],
)
def test_render_processes(
    monkeypatch: pytest.MonkeyPatch, gl: str, cpus: int, expected: int
) -> None:
    monkeypatch.setenv("MUJOCO_GL", gl)
    monkeypatch.setattr(world_cameras.os, "sched_getaffinity", lambda pid: set(range(cpus)))
    assert render_processes() == expected
