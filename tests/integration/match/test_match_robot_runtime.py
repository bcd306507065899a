"""A robot container under the league's ``robot_runtime`` on the real engine: gVisor's ``runsc``
(Debian's ``runsc`` package) registered in the engine's daemon.json as configs/README.md says.
Under gVisor the container sees gVisor's kernel (it reports Linux 4.4.0), not the host's."""

from __future__ import annotations

import os
import uuid
from pathlib import Path
from typing import Any

import pytest

from orchestrator.engine import LABEL_MATCH, LABEL_PROJECT
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
        security_opt=("no-new-privileges",), pids_limit=64, runtime=runtime_name)
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
