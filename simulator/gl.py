"""The offscreen OpenGL back end of MuJoCo, chosen before ``mujoco`` is imported.

MuJoCo reads ``MUJOCO_GL`` once, when it is imported, and a back end that fails to load cannot
be swapped in the same process. So each candidate is tried in a short child process that imports
MuJoCo and makes a 64x64 context current; the first that works is written to ``MUJOCO_GL`` (and
``PYOPENGL_PLATFORM``) of this process. A ``MUJOCO_GL`` set by the user is the only candidate.

This module imports neither MuJoCo nor OpenGL.
"""

from __future__ import annotations

import os
import subprocess
import sys
from collections.abc import Callable, MutableMapping, Sequence

from simulator.errors import OffscreenGLError

OFFSCREEN_BACKENDS = ("egl", "osmesa")
PROBE_TIMEOUT_S = 60.0

_PROBE = (
    "import mujoco\n"
    "context = mujoco.GLContext(64, 64)\n"
    "context.make_current()\n"
    "context.free()\n"
)

Probe = Callable[[str], str | None]
"""back end -> None when it works, else why not (one line)."""


def probe_backend(backend: str) -> str | None:
    """Try ``backend`` in a child process; None when it works, else the reason."""
    env = dict(os.environ, MUJOCO_GL=backend, PYOPENGL_PLATFORM=backend)
    try:
        done = subprocess.run(
            [sys.executable, "-c", _PROBE],
            env=env, capture_output=True, text=True, timeout=PROBE_TIMEOUT_S, check=False,
        )  # fmt: skip
    except subprocess.TimeoutExpired:
        return f"no context within {PROBE_TIMEOUT_S:g} s"
    if done.returncode == 0:
        return None
    lines = [line.strip() for line in done.stderr.splitlines() if line.strip()]
    return lines[-1] if lines else f"exit code {done.returncode}"


def choose_offscreen_gl(
    env: MutableMapping[str, str] | None = None,
    *,
    candidates: Sequence[str] = OFFSCREEN_BACKENDS,
    probe: Probe = probe_backend,
) -> str:
    """Set ``MUJOCO_GL`` to the first offscreen back end that works and return it.

    Raises:
        OffscreenGLError: no candidate works (each one tried, with its reason).
    """
    env = os.environ if env is None else env
    requested = env.get("MUJOCO_GL", "").strip()
    tried: list[tuple[str, str]] = []
    for backend in (requested,) if requested else tuple(candidates):
        reason = probe(backend)
        if reason is None:
            env["MUJOCO_GL"] = backend
            env.setdefault("PYOPENGL_PLATFORM", backend)
            return backend
        tried.append((backend, reason))
    raise OffscreenGLError(tried=tuple(tried), from_environment=bool(requested))


__all__ = ["OFFSCREEN_BACKENDS", "choose_offscreen_gl", "probe_backend"]
