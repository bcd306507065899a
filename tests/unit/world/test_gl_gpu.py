"""The simulator's OpenGL under the ``gpu`` setting: EGL kept only with a hardware renderer,
``auto`` falling back to OSMesa, ``on`` refusing; and which renderer a process really got."""

from __future__ import annotations

import logging

import pytest

from simulator.errors import GpuRenderError
from simulator.gl import GLInfo, probe_gl_info, read_gl_info, select_match_gl

NVIDIA = GLInfo(backend="egl", vendor="NVIDIA Corporation", renderer="NVIDIA L4/PCIe/SSE2",
                version="4.6.0 NVIDIA 550.54.15")
LLVMPIPE = GLInfo(backend="egl", vendor="Mesa/X.org", renderer="llvmpipe (LLVM 15.0.6, 256 bits)",
                  version="4.5 (Compatibility Profile) Mesa 22.3.6")


def _probe(answer: GLInfo | str, calls: list[str]) -> object:
    def probe(backend: str) -> GLInfo | str:
        calls.append(backend)
        return answer

    return probe


def _gpu_env(mode: str) -> dict[str, str]:
    return {"HLVS_GPU": mode, "MUJOCO_GL": "egl", "PYOPENGL_PLATFORM": "egl",
            "MUJOCO_EGL_DEVICE_ID": "0"}


@pytest.mark.parametrize("mode", ["on", "auto"])
def test_egl_on_a_gpu_is_kept(mode: str) -> None:
    env, calls = _gpu_env(mode), list[str]()
    assert select_match_gl(env, probe=_probe(NVIDIA, calls)) == "egl"  # type: ignore[arg-type]
    assert calls == ["egl"] and env["MUJOCO_GL"] == "egl" and env["PYOPENGL_PLATFORM"] == "egl"


@pytest.mark.parametrize("answer", [LLVMPIPE, "EGLError: eglInitialize failed"])
def test_auto_falls_back_to_osmesa_with_a_warning(answer: GLInfo | str,
                                                  caplog: pytest.LogCaptureFixture) -> None:
    env = _gpu_env("auto")
    with caplog.at_level(logging.WARNING, logger="simulator.gl"):
        assert select_match_gl(env, probe=_probe(answer, [])) == "osmesa"  # type: ignore[arg-type]
    assert env["MUJOCO_GL"] == "osmesa" and env["PYOPENGL_PLATFORM"] == "osmesa"
    (record,) = caplog.records
    why = "software renderer llvmpipe" if isinstance(answer, GLInfo) else "eglInitialize failed"
    assert record.getMessage().startswith("gpu auto: no GPU rendering in the simulator (")
    assert why in record.getMessage() and "on the CPU with osmesa" in record.getMessage()


@pytest.mark.parametrize("answer", [LLVMPIPE, "EGLError: eglInitialize failed"])
def test_on_refuses_anything_but_a_gpu(answer: GLInfo | str) -> None:
    env = _gpu_env("on")
    with pytest.raises(GpuRenderError) as caught:
        select_match_gl(env, probe=_probe(answer, []))  # type: ignore[arg-type]
    assert str(caught.value).startswith('gpu "on": the simulator cannot render on the GPU (')
    assert '"auto" or "off"' in str(caught.value)
    assert env["MUJOCO_GL"] == "egl"  # nothing chosen behind the user's back


def test_without_a_gpu_osmesa_is_the_default_and_nothing_is_probed() -> None:
    env: dict[str, str] = {}
    calls: list[str] = []
    assert select_match_gl(env, probe=_probe(NVIDIA, calls)) == "osmesa"  # type: ignore[arg-type]
    assert env == {"MUJOCO_GL": "osmesa", "PYOPENGL_PLATFORM": "osmesa"} and calls == []
    mine = {"MUJOCO_GL": "egl"}  # set by the user, no GPU granted: kept as it is
    assert select_match_gl(mine, probe=_probe(LLVMPIPE, calls)) == "egl"  # type: ignore[arg-type]
    assert calls == []


def test_software_renderers_are_told_from_gpus() -> None:
    assert LLVMPIPE.software and not NVIDIA.software
    assert GLInfo(backend="osmesa", vendor="Mesa", renderer="softpipe", version="3.3").software
    assert NVIDIA.record() == {"gl_backend": "egl", "gl_vendor": "NVIDIA Corporation",
                               "gl_renderer": "NVIDIA L4/PCIe/SSE2",
                               "gl_version": "4.6.0 NVIDIA 550.54.15"}
    assert NVIDIA.describe().endswith(", GPU)") and LLVMPIPE.describe().endswith(", CPU)")


def test_this_process_renders_on_the_cpu() -> None:
    """The tests run with OSMesa (tests/conftest.py) on a machine without a GPU: the strings
    come from the real driver."""
    info = read_gl_info()
    assert info.backend == "osmesa"
    assert "llvmpipe" in info.renderer and info.software
    assert info.vendor and info.version


def test_the_child_probe_reads_the_real_driver_or_says_why_not() -> None:
    info = probe_gl_info("osmesa")
    assert isinstance(info, GLInfo) and info.backend == "osmesa" and info.software
    failed = probe_gl_info("nonesuch")
    assert isinstance(failed, str) and "MUJOCO_GL" in failed and "nonesuch" in failed
