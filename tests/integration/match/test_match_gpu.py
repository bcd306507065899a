"""The ``gpu`` setting on a machine without a GPU, for real: ``on`` is refused before anything
starts; ``auto`` plays on the CPU when the engine refuses the GPU; the simulator image's EGL (the
glvnd dispatcher that an NVIDIA driver plugs into) loads, and the simulator under ``HLVS_GPU``
falls back from a software EGL renderer (auto) or refuses it (on). That the default ``auto``
plays a scrimmage with its cameras on the CPU and says so is checked on the short scrimmage of
test_match_scrimmage.py (the same match)."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import docker
import pytest

from hlvs.cli import main as hlvs
from orchestrator.engine.gpu import device_files
from orchestrator.errors import OrchestratorError
from orchestrator.match import gpu
from tests.conftest import TEST_LABEL

pytestmark = [pytest.mark.docker, pytest.mark.root]


@pytest.fixture(scope="module")
def images() -> str:
    if device_files():
        pytest.skip("this host has an NVIDIA GPU: these tests are about the CPU fallback")
    try:
        from orchestrator.project_images import project_image

        project_image("stub")
        return str(project_image("simulator"))
    except (ImportError, OrchestratorError) as exc:
        pytest.skip(f"project images unavailable: {exc}")



def _scrimmage(match_id: str, out: Path, *, half_duration_s: int) -> int:
    """A short default scrimmage; its containers are removed whatever happens."""
    try:
        return hlvs(["scrimmage", "--out", str(out), "--half-duration", str(half_duration_s),
                     "--ready-duration", "2", "--minimum-play", "0", "--wait-before-ready", "1",
                     "--grace", "2", "--match-id", match_id])
    finally:
        hlvs(["cleanup", "--match", match_id])


def test_on_without_a_gpu_is_refused_naming_the_option(
    images: str, tmp_path: Path, runtime: Any, capsys: pytest.CaptureFixture[str],
) -> None:
    match_id = "gpu-on-test"
    code = hlvs(["scrimmage", "--out", str(tmp_path / "on"), "--gpu", "on",
                 "--match-id", match_id])
    printed = capsys.readouterr()
    assert code == 2
    assert 'command line: --gpu: "on" but no NVIDIA GPU that Docker can use here' in printed.err
    assert "Traceback" not in printed.err
    assert runtime.list_project(match_id=match_id) == []


def test_auto_plays_on_the_cpu_when_the_engine_refuses_the_gpu(
    images: str, tmp_path: Path, runtime: Any, capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """Detection fooled into seeing a GPU: the real engine gets the device request, refuses it
    (it has no NVIDIA device driver), and the simulator starts again without it."""
    from orchestrator.engine import gpu as engine_gpu

    monkeypatch.setattr(engine_gpu, "detect_nvidia", lambda client: gpu.GpuDetection(
        access="device-request", devices=("/dev/nvidia0", "/dev/nvidiactl"), via="a test"))
    match_id = "gpu-refused-test"
    out = tmp_path / "refused"
    code = _scrimmage(match_id, out, half_duration_s=2)
    printed = capsys.readouterr()
    assert code == 0, printed.err[-3000:]
    assert "the engine refused the simulator the GPU" in printed.err
    assert 'could not select device driver "" with capabilities: [[gpu]]' in printed.err
    cameras = json.loads((out / "public" / "sim_result.json").read_text())["cameras"]
    assert cameras["gl_backend"] == "osmesa" and "llvmpipe" in cameras["gl_renderer"]
    assert runtime.list_project(match_id=match_id) == []


def _in_simulator_image(client: docker.DockerClient, image: str, environment: dict[str, str],
                        command: list[str]) -> tuple[int, str, str]:
    """Exit code, standard output, standard output and error (the two streams read apart:
    interleaved, the order of their last lines is a race)."""
    container = client.containers.run(
        image, command=command, environment=environment, labels={TEST_LABEL: "gpu"},
        network_mode="none", detach=True,
    )
    try:
        code = int(container.wait(timeout=120)["StatusCode"])
        stdout = container.logs(stdout=True, stderr=False).decode("utf-8", "replace")
        stderr = container.logs(stdout=False, stderr=True).decode("utf-8", "replace")
        return code, stdout, stdout + stderr
    finally:
        container.remove(force=True)


def test_the_simulator_image_loads_egl_and_keeps_only_a_gpu(
    images: str, docker_client: docker.DockerClient,
) -> None:
    egl = {"MUJOCO_GL": "egl", "PYOPENGL_PLATFORM": "egl", "MUJOCO_EGL_DEVICE_ID": "0"}
    code, printed, output = _in_simulator_image(docker_client, images, egl, [
        "python", "-c", "import json\nfrom simulator.gl import probe_gl_info, select_match_gl\n"
        "import os\nprint(json.dumps(probe_gl_info('egl').record()))\n"
        "print(select_match_gl())\n"])
    # glvnd's libEGL.so.1 found Mesa's vendor file: the NVIDIA one plugs in the same way
    assert code == 0, output
    first, chosen = printed.strip().splitlines()[-2:]
    assert json.loads(first)["gl_backend"] == "egl" and "llvmpipe" in first
    assert chosen == "egl"  # no HLVS_GPU: a MUJOCO_GL of the environment is kept
    auto = {**egl, "HLVS_GPU": "auto"}
    code, printed, output = _in_simulator_image(docker_client, images, auto, [
        "python", "-c", "import os\nfrom simulator.gl import select_match_gl\n"
        "print(select_match_gl(), os.environ['MUJOCO_GL'])\n"])
    assert code == 0, output
    assert printed.strip().splitlines()[-1] == "osmesa osmesa"
    assert "EGL gave the software renderer llvmpipe" in output
    code, _, output = _in_simulator_image(docker_client, images, {**egl, "HLVS_GPU": "on"},
                                       ["run", "--spec", "/nonexistent.json", "--out", "/tmp/o"])
    assert code == 3, output
    assert 'gpu "on": the simulator cannot render on the GPU (EGL gave the software renderer ' \
           "llvmpipe" in output
