"""A robot container under the league's ``robot_runtime`` on the real engine: gVisor's ``runsc``
(Debian's ``runsc`` package) registered in the engine's daemon.json as configs/README.md says.
Under gVisor the container sees gVisor's kernel (it reports Linux 4.4.0), not the host's."""

from __future__ import annotations

import argparse
import json
import os
import time
import uuid
from pathlib import Path
from typing import Any

import pytest

from hlvs.cli import main as hlvs
from orchestrator import add_scrimmage_arguments
from orchestrator.config import Limits
from orchestrator.engine import LABEL_MATCH, LABEL_PROJECT
from orchestrator.match.layout import robot_pids_limit
from orchestrator.match.scrimmage import ScrimmageRequest, write_files
from orchestrator.runtime.port import ContainerRequest

pytestmark = [pytest.mark.docker]


@pytest.mark.parametrize("runtime_name", ["runsc", None])
def test_a_robot_container_runs_under_the_named_runtime(
        docker_client: Any, runtime: Any, tmp_path: Path, runtime_name: str | None) -> None:
    registered = docker_client.info().get("Runtimes", {})
    if runtime_name is not None and runtime_name not in registered:
        pytest.skip(f"the engine has no {runtime_name} runtime (see configs/README.md)")
    match_id = f"rt-{uuid.uuid4().hex[:8]}"
    request = ContainerRequest(
        name=f"hlvs-{match_id}-red-1", image="hlvs-runner/stub:latest",
        command=("uname", "-r"), labels={LABEL_PROJECT: "1", LABEL_MATCH: match_id},
        network_mode="none", read_only=True, cap_drop=("ALL",),
        security_opt=("no-new-privileges",),
        pids_limit=robot_pids_limit(Limits(pids=64, robot_runtime=runtime_name or "")),
        runtime=runtime_name)
    container = runtime.create_container(request)
    try:
        runtime.start(container)
        assert runtime.wait(container, timeout_s=60) == 0
        runtime.save_logs(container, stdout=tmp_path / "out", stderr=tmp_path / "err")
        kernel = (tmp_path / "out").read_text().strip()
        assert docker_client.api.inspect_container(container)["HostConfig"]["Runtime"] == (
            runtime_name or "runc")
    finally:
        runtime.remove(container)
    if runtime_name == "runsc":
        assert kernel == "4.4.0", kernel  # gVisor's own kernel
    else:
        assert kernel == os.uname().release


def test_the_smallest_pids_limit_leaves_runsc_room_for_its_own_tasks(
        docker_client: Any, runtime: Any) -> None:
    """runsc's sentry and gofer run in the robot container's pids cgroup (44 to 50 tasks idle
    here): with the engine's limit at the game's ``pids`` alone, a robot under runsc with the
    smallest ``pids`` (16) could not start, and one with 64 ended with exit 2 now and then when
    a program of its started or ended. With the sandbox's room added, a robot with 16 starts
    forty programs one after another and ends with 0; the limit the engine holds is 16 + the
    room."""
    if "runsc" not in docker_client.info().get("Runtimes", {}):
        pytest.skip("the engine has no runsc runtime (see configs/README.md)")
    match_id = f"rt-{uuid.uuid4().hex[:8]}"
    limit = robot_pids_limit(Limits(pids=16, robot_runtime="runsc"))
    request = ContainerRequest(
        name=f"hlvs-{match_id}-red-1", image="hlvs-runner/stub:latest",
        command=("sh", "-c", "for i in $(seq 40); do sh -c 'exit 0' || exit 9; done"),
        labels={LABEL_PROJECT: "1", LABEL_MATCH: match_id}, network_mode="none",
        read_only=True, cap_drop=("ALL",), security_opt=("no-new-privileges",),
        pids_limit=limit, runtime="runsc")
    container = runtime.create_container(request)
    try:
        runtime.start(container)
        assert runtime.wait(container, timeout_s=60) == 0
        assert docker_client.api.inspect_container(container)["HostConfig"]["PidsLimit"] == (
            16 + 128)
    finally:
        runtime.remove(container)


def test_a_runtime_the_engine_lacks_refuses_the_match_before_any_container(
        docker_client: Any, runtime: Any, test_image: str, tmp_path: Path,
        capsys: pytest.CaptureFixture[str]) -> None:
    """Before, each robot's start failed with the engine's message once the networks and the
    simulator were up; now ``hlvs match`` exits 2 naming the setting and the engine, and the
    engine has nothing of the match."""
    match_id = f"rt-{uuid.uuid4().hex[:8]}"
    parser = argparse.ArgumentParser()
    add_scrimmage_arguments(parser)
    write_files(ScrimmageRequest.from_options(parser.parse_args([
        "--players", "1", "--half-duration", "3", "--minimum-play", "0", "--match-id", match_id,
        "--red-image", test_image, "--blue-image", test_image])), tmp_path / "config")
    game_path = tmp_path / "config" / "game.json"
    game = json.loads(game_path.read_text())
    game.setdefault("limits", {})["robot_runtime"] = "no-such-runtime"
    game_path.write_text(json.dumps(game))
    began = int(time.time()) - 1
    try:
        code = hlvs(["match", str(game_path), "--out", str(tmp_path / "out")])
    finally:
        hlvs(["cleanup", "--match", match_id])
    seen = [f"{e.get('Type')} {e.get('Action')}" for e in docker_client.events(
        since=began, until=int(time.time()) + 1, decode=True,
        filters={"label": f"{LABEL_MATCH}={match_id}"})]
    err = capsys.readouterr().err
    assert code == 2, err[-2000:]
    assert str(game_path) in err and "/limits/robot_runtime" in err, err
    assert "'no-such-runtime'" in err and "Docker engine at unix://" in err, err
    assert "Traceback" not in err
    assert seen == [], seen  # no network, no container: not even created
