"""Log levels as the README promises: ``-v`` shows this project's lines, never the libraries'
INFO or DEBUG lines (Alembic, OpenGL, urllib3)."""

from __future__ import annotations

import logging

import pytest

from hlvs.cli import configure_logging


@pytest.mark.parametrize("level", [logging.DEBUG, logging.INFO, logging.WARNING])
def test_libraries_stay_at_warning(level: int) -> None:
    configure_logging(level)
    try:
        for name in ("alembic.runtime.plugins", "OpenGL.acceleratesupport",
                     "urllib3.connectionpool", "docker.utils.config"):
            library = logging.getLogger(name)
            assert not library.isEnabledFor(logging.INFO), name
            assert library.isEnabledFor(logging.WARNING), name
        assert logging.getLogger("service.worker").isEnabledFor(level)
    finally:
        configure_logging(logging.WARNING)


def test_render_shows_no_library_info_lines(tmp_path: object) -> None:
    """``hlvs render`` runs the simulator's render in a process of its own, logging at INFO:
    its lines, not OpenGL's."""
    import os
    import subprocess
    import sys
    from pathlib import Path

    replay = Path(str(tmp_path)) / "bad.hlvsrec"
    replay.write_bytes(b"not a replay")
    env = {**os.environ, "MUJOCO_GL": "osmesa", "PYOPENGL_PLATFORM": "osmesa"}
    proc = subprocess.run([sys.executable, "-m", "simulator", "render", str(replay)],
                          capture_output=True, text=True, timeout=120, env=env, check=False,
                          cwd=Path(__file__).parents[2])
    assert "bad magic" in proc.stderr, proc.stderr[-2000:]
    assert "INFO simulator.render" in proc.stderr  # its own INFO lines are kept
    assert "OpenGL." not in proc.stderr.replace("offscreen OpenGL back end", ""), proc.stderr
