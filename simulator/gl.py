"""The offscreen OpenGL back end of MuJoCo, chosen before ``mujoco`` is imported.

MuJoCo reads ``MUJOCO_GL`` once, when it is imported, and a back end that fails to load cannot
be swapped in the same process. So each candidate is tried in a short child process that imports
MuJoCo and makes a 64x64 context current; the first that works is written to ``MUJOCO_GL`` (and
``PYOPENGL_PLATFORM``) of this process. A ``MUJOCO_GL`` set by the user is the only candidate.

The simulator of a match (:func:`select_match_gl`) renders with OSMesa unless the orchestrator
gave it the host's NVIDIA GPU (``HLVS_GPU`` = ``on`` or ``auto`` with ``MUJOCO_GL=egl``): then
EGL is tried in a child process and kept only when it gives a hardware renderer; under ``auto``
anything else falls back to OSMesa with a warning, under ``on`` it is an error.
:func:`read_gl_info` tells which renderer a process actually got (``GL_VENDOR``,
``GL_RENDERER``), for the log, ``sim_result.json`` and ``hlvs bench api --camera``.

This module imports neither MuJoCo nor OpenGL at module level.
"""

from __future__ import annotations

import json
import logging
import os
import subprocess
import sys
from collections.abc import Callable, MutableMapping, Sequence
from dataclasses import dataclass

from contracts import GPU_ENVIRONMENT  # on | auto: the orchestrator gave us the GPU
from simulator.errors import GpuRenderError, OffscreenGLError

log = logging.getLogger(__name__)

OFFSCREEN_BACKENDS = ("egl", "osmesa")
PROBE_TIMEOUT_S = 60.0
# GL_RENDERER of Mesa's CPU rasterisers (and of other software renderers)
SOFTWARE_RENDERERS = ("llvmpipe", "softpipe", "swrast", "software")

_PROBE = (
    "import mujoco\n"
    "context = mujoco.GLContext(64, 64)\n"
    "context.make_current()\n"
    "context.free()\n"
)

Probe = Callable[[str], str | None]
"""back end -> None when it works, else why not (one line)."""


def _run_probe(backend: str, code: str) -> subprocess.CompletedProcess[str] | str:
    """Run ``code`` in a child process with ``backend``: its result when it exited 0, else
    the reason it failed (one line)."""
    env = dict(os.environ, MUJOCO_GL=backend, PYOPENGL_PLATFORM=backend)
    try:
        done = subprocess.run(
            [sys.executable, "-c", code],
            env=env, capture_output=True, text=True, timeout=PROBE_TIMEOUT_S, check=False,
        )  # fmt: skip
    except subprocess.TimeoutExpired:
        return f"no context within {PROBE_TIMEOUT_S:g} s"
    if done.returncode == 0:
        return done
    lines = [line.strip() for line in done.stderr.splitlines() if line.strip()]
    return lines[-1] if lines else f"exit code {done.returncode}"


def probe_backend(backend: str) -> str | None:
    """Try ``backend`` in a child process; None when it works, else the reason."""
    done = _run_probe(backend, _PROBE)
    return done if isinstance(done, str) else None


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


@dataclass(frozen=True, slots=True, kw_only=True)
class GLInfo:
    """Which OpenGL a process renders with: ``backend`` is ``MUJOCO_GL``, the rest the strings
    of the driver (``GL_VENDOR``, ``GL_RENDERER``, ``GL_VERSION``)."""

    backend: str
    vendor: str
    renderer: str
    version: str

    @property
    def software(self) -> bool:
        """A CPU rasteriser (Mesa's llvmpipe, softpipe, swrast), not a GPU."""
        return any(name in self.renderer.lower() for name in SOFTWARE_RENDERERS)

    def record(self) -> dict[str, str]:
        """The ``gl_*`` keys of ``sim_result.json`` cameras and ``bench api --camera``."""
        return {
            "gl_backend": self.backend,
            "gl_vendor": self.vendor,
            "gl_renderer": self.renderer,
            "gl_version": self.version,
        }

    def describe(self) -> str:
        kind = "CPU" if self.software else "GPU"
        return f"{self.backend}: {self.renderer} ({self.vendor}, OpenGL {self.version}, {kind})"


def read_gl_info() -> GLInfo:
    """The OpenGL this process renders with (MuJoCo imported with its ``MUJOCO_GL``): a 1x1
    context is made current, its strings read and the context freed (a few ms).

    Raises:
        OffscreenGLError: no context could be made.
    """
    import mujoco

    backend = os.environ.get("MUJOCO_GL", "")
    if not hasattr(mujoco, "GLContext"):
        raise OffscreenGLError(tried=((backend or "unset", "MuJoCo has no GL context"),),
                               from_environment=bool(backend))
    try:
        context = mujoco.GLContext(1, 1)
    except Exception as exc:  # the back ends raise their own library errors
        raise OffscreenGLError(tried=((backend, f"{type(exc).__name__}: {exc}"),),
                               from_environment=True) from exc
    try:
        context.make_current()
        from OpenGL import GL

        vendor, renderer, version = (
            _text(GL.glGetString(name)) for name in (GL.GL_VENDOR, GL.GL_RENDERER, GL.GL_VERSION)
        )
    finally:
        context.free()
    return GLInfo(backend=backend, vendor=vendor, renderer=renderer, version=version)


def _text(value: object) -> str:
    if isinstance(value, bytes):
        return value.decode("utf-8", "replace")
    return "" if value is None else str(value)


_INFO_PROBE = (
    "import json\n"
    "from simulator.gl import read_gl_info\n"
    "print(json.dumps(read_gl_info().record()))\n"
)

InfoProbe = Callable[[str], "GLInfo | str"]
"""back end -> its GLInfo when a context works, else why not (one line)."""


def probe_gl_info(backend: str) -> GLInfo | str:
    """:func:`read_gl_info` for ``backend`` in a child process; the reason when it fails."""
    done = _run_probe(backend, _INFO_PROBE)
    if isinstance(done, str):
        return done
    try:
        record = json.loads(done.stdout.strip().splitlines()[-1])
        return GLInfo(backend=backend, vendor=record["gl_vendor"],
                      renderer=record["gl_renderer"], version=record["gl_version"])
    except (ValueError, IndexError, KeyError, TypeError):
        return f"unreadable probe output {done.stdout.strip()[:200]!r}"


def select_match_gl(
    env: MutableMapping[str, str] | None = None, *, probe: InfoProbe = probe_gl_info
) -> str:
    """Set the back end of a match's simulator before MuJoCo is imported and return it.

    With ``HLVS_GPU`` ``on`` or ``auto`` and ``MUJOCO_GL=egl`` (the orchestrator gave the
    container the GPU), EGL is kept when it gives a hardware renderer; otherwise ``auto`` falls
    back to ``osmesa`` (with a warning) and ``on`` raises. Without them, a ``MUJOCO_GL`` set in
    the environment is kept and ``osmesa`` is the default.

    Raises:
        GpuRenderError: ``HLVS_GPU=on`` and EGL failed or gave a software renderer.
    """
    env = os.environ if env is None else env
    asked = env.get(GPU_ENVIRONMENT, "").strip()
    if asked in ("on", "auto") and env.get("MUJOCO_GL", "").strip() == "egl":
        found = probe("egl")
        if isinstance(found, GLInfo) and not found.software:
            log.info("gpu %s: cameras render on %s", asked, found.describe())
            return "egl"
        why = (found if isinstance(found, str)
               else f"EGL gave the software renderer {found.renderer}")
        if asked == "on":
            raise GpuRenderError(reason=why)
        log.warning("gpu auto: no GPU rendering in the simulator (%s); cameras render on the CPU "
                    "with osmesa", why)
        env["MUJOCO_GL"] = env["PYOPENGL_PLATFORM"] = "osmesa"
        return "osmesa"
    env.setdefault("MUJOCO_GL", "osmesa")
    env.setdefault("PYOPENGL_PLATFORM", env["MUJOCO_GL"])
    return env["MUJOCO_GL"]


__all__ = [
    "GPU_ENVIRONMENT",
    "OFFSCREEN_BACKENDS",
    "GLInfo",
    "choose_offscreen_gl",
    "probe_backend",
    "probe_gl_info",
    "read_gl_info",
    "select_match_gl",
]
