"""The robots' start gate on the real engine, under the engine's default runtime and gVisor's
runsc: the image's program does not run until the gate's file exists, then runs as the engine
would have run it (its entry point on PATH, its arguments); a program that does not exist ends
the container with 127 and says so."""

from __future__ import annotations

import time
import uuid
from pathlib import Path
from typing import Any

import pytest

from orchestrator.config import Limits
from orchestrator.engine import LABEL_MATCH, LABEL_PROJECT
from orchestrator.match import gate
from orchestrator.match.layout import robot_pids_limit
from orchestrator.runtime.port import BindMount, ContainerRequest

pytestmark = [pytest.mark.docker]


def _gated(runtime: Any, docker_client: Any, tmp_path: Path, runtime_name: str | None,
           program: tuple[str, ...], *, image_entrypoint: bool = True
           ) -> tuple[str, Path, Path]:
    """A started container of the stub image behind the gate running ``program`` (after the
    image's entry point unless ``image_entrypoint`` is False); its gate folder and a folder it
    may write (bound at /out)."""
    binary = gate.start_gate()
    if binary is None:
        pytest.skip("no C compiler with a static C library to build the start gate")
    if runtime_name is not None and runtime_name not in docker_client.info().get("Runtimes", {}):
        pytest.skip(f"the engine has no {runtime_name} runtime (see configs/README.md)")
    folder = gate.folder(tmp_path, "red-1")
    out = tmp_path / "out"
    out.mkdir()
    out.chmod(0o777)
    match_id = f"gate-{uuid.uuid4().hex[:8]}"
    image = "hlvs-runner/stub:latest"
    launch = runtime.image_launch(image) if image_entrypoint else ((), ())
    entrypoint, command = gate.gated_launch((gate.TARGET, gate.DIR_TARGET, "--"), program,
                                            launch)
    request = ContainerRequest(
        name=f"hlvs-{match_id}-red-1", image=image, entrypoint=entrypoint, command=command,
        labels={LABEL_PROJECT: "1", LABEL_MATCH: match_id}, network_mode="none",
        read_only=True, cap_drop=("ALL",), security_opt=("no-new-privileges",),
        pids_limit=robot_pids_limit(Limits(pids=64, robot_runtime=runtime_name or "")),
        runtime=runtime_name,
        mounts=(BindMount(source=binary, target=gate.TARGET, read_only=True),
                BindMount(source=folder, target=gate.DIR_TARGET, read_only=True),
                BindMount(source=out, target="/out")),
    )
    container = runtime.create_container(request)
    runtime.start(container)
    return container, folder, out


def _wait_exit(runtime: Any, container: str, timeout_s: float = 20.0) -> Any:
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        state = runtime.inspect(container)
        if state.exited:
            return state
        time.sleep(0.05)
    raise AssertionError(f"{container} still runs after {timeout_s} s")


def _output(docker_client: Any, container: str) -> str:
    """What the container printed, for a failure's message."""
    logs: bytes = docker_client.api.logs(container, stdout=True, stderr=True)
    return logs.decode(errors="replace")


@pytest.mark.parametrize("runtime_name", [None, "runsc"])
def test_the_program_runs_only_once_released(
        docker_client: Any, runtime: Any, tmp_path: Path, runtime_name: str | None) -> None:
    # through the image's entry point (a shell script that runs a program on PATH)
    container, folder, out = _gated(runtime, docker_client, tmp_path, runtime_name,
                                    ("sh", "-c", 'echo "$0 $1" > /out/ran', "a", "b c"))
    try:
        time.sleep(1.5)
        state = runtime.inspect(container)
        assert state.running and not state.exited
        assert not (out / "ran").exists()  # held at the gate
        gate.release(folder)
        state = _wait_exit(runtime, container)
        assert state.exit_code == 0, _output(docker_client, container)
        assert (out / "ran").read_text() == "a b c\n"  # the arguments as given
    finally:
        runtime.remove(container)


@pytest.mark.parametrize("runtime_name", [None, "runsc"])
def test_a_missing_program_ends_with_127(
        docker_client: Any, runtime: Any, tmp_path: Path, runtime_name: str | None) -> None:
    container, folder, _ = _gated(runtime, docker_client, tmp_path, runtime_name,
                                  ("/no/such/program",), image_entrypoint=False)
    try:
        gate.release(folder)
        state = _wait_exit(runtime, container)
        assert state.exit_code == 127
        logs = docker_client.api.logs(container, stdout=False, stderr=True).decode()
        assert "start gate: cannot run /no/such/program: No such file or directory" in logs
    finally:
        runtime.remove(container)
