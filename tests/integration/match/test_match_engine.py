"""DockerRuntime against the real engine: lifecycle, logs, copy out, stats, wait, and the
translation of engine errors into orchestrator errors."""

from __future__ import annotations

import uuid
from pathlib import Path
from typing import Any

import pytest

from orchestrator.errors import InfrastructureError
from orchestrator.runtime.port import (
    ContainerRequest,
    NetworkRequest,
    ObjectNotFound,
    SubnetInUse,
)
from tests.conftest import TEST_LABEL

pytestmark = [pytest.mark.docker]


def test_container_lifecycle_logs_copy_and_exit_code(runtime: Any, test_image: str,
                                                     tmp_path: Path) -> None:
    name = f"hlvs-enginetest-{uuid.uuid4().hex[:6]}"
    container_id = runtime.create_container(ContainerRequest(
        name=name, image=test_image,
        command=("sh", "-c", "echo out; echo err >&2; echo data > /tmp/f.txt; sleep 3; exit 7"),
        labels={TEST_LABEL: "1", "org.hlvs-runner": "1"}, cap_drop=("ALL",),
        mem_bytes=64 * 2**20,
    ))
    try:
        assert runtime.inspect(container_id).status == "created"
        assert runtime.inspect(container_id).exit_code is None
        runtime.start(container_id)
        samples = runtime.stats_stream(container_id)
        first = next(samples)
        assert first.memory_bytes > 0
        assert runtime.wait(container_id, timeout_s=30) == 7
        state = runtime.inspect(container_id)
        assert state.exited and state.exit_code == 7 and not state.oom_killed
        runtime.save_logs(container_id, stdout=tmp_path / "o.log", stderr=tmp_path / "e.log")
        assert (tmp_path / "o.log").read_text() == "out\n"
        assert (tmp_path / "e.log").read_text() == "err\n"
        runtime.copy_out(container_id, "/tmp/f.txt", tmp_path / "copied")
        assert (tmp_path / "copied" / "f.txt").read_text() == "data\n"
        assert any(o.name == name for o in runtime.list_project())
    finally:
        runtime.remove(container_id)
    with pytest.raises(ObjectNotFound) as info:
        runtime.inspect(container_id)
    assert info.value.kind == "container" and info.value.name == container_id


def test_engine_errors_become_orchestrator_errors(runtime: Any) -> None:
    with pytest.raises(InfrastructureError) as info:
        runtime.create_container(ContainerRequest(
            name=f"hlvs-enginetest-{uuid.uuid4().hex[:6]}", image="hlvs-runner-test/none:0",
            labels={TEST_LABEL: "1"}))
    assert "No such image: hlvs-runner-test/none:0" in str(info.value)
    name = f"hlvs-enginetest-{uuid.uuid4().hex[:6]}"
    request = NetworkRequest(name=name, subnet="10.213.253.0/24", gateway="10.213.253.1",
                             internal=True, bridge_name=f"hlt{uuid.uuid4().hex[:8]}",
                             labels={TEST_LABEL: "1"})
    runtime.create_network(request)
    try:
        clash = NetworkRequest(name=name + "b", subnet="10.213.253.0/24",
                               gateway="10.213.253.1", internal=True,
                               bridge_name=f"hlt{uuid.uuid4().hex[:8]}", labels={TEST_LABEL: "1"})
        with pytest.raises(SubnetInUse) as clash_info:
            runtime.create_network(clash)
        assert clash_info.value.subnet == "10.213.253.0/24"
    finally:
        runtime.remove_network(name)
