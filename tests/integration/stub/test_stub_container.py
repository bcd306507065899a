"""The stub image: stops cleanly on ``docker stop`` (SIGTERM, exit 0), ``ignore-sigterm`` is
killed after the grace time, and the robot log lands in the mounted /robocup-logs."""

from __future__ import annotations

import os
import uuid
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

from tests.conftest import TEST_LABEL

pytestmark = pytest.mark.docker


@pytest.fixture(scope="module")
def stub_image() -> str:
    from orchestrator.project_images import project_image

    return str(project_image("stub"))


# the label value of this run's containers: the fixture removes these and no other test's
_RUN = uuid.uuid4().hex[:12]


@pytest.fixture()
def engine() -> Iterator[Any]:
    from orchestrator.engine import connect

    client = connect()
    yield client
    for container in client.containers.list(all=True, filters={"label": f"{TEST_LABEL}={_RUN}"}):
        container.remove(force=True)
    client.close()


def _run(engine: Any, image: str, command: list[str], logs: Path) -> Any:
    logs.mkdir(parents=True, exist_ok=True)
    os.chmod(logs, 0o777)
    return engine.containers.run(
        image,
        command=command,
        detach=True,
        name=f"hlvs-test-stub-{uuid.uuid4().hex[:8]}",
        labels={TEST_LABEL: _RUN},
        network_mode="none",
        environment={
            "ROBOCUP_ROBOT_ID": "3",
            "ROBOCUP_TEAM_COLOR": "blue",
            "ROBOCUP_SIMULATOR_ADDR": "127.0.0.1:10023",
            "ROBOCUP_MIRROR_SERVER_IP": "127.0.0.1",
        },
        volumes={str(logs): {"bind": "/robocup-logs", "mode": "rw"}},
    )


def _wait_for(path: Path, text: str, timeout_s: float = 60.0) -> None:
    import time

    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        if path.exists() and text in path.read_text():
            return
        time.sleep(0.1)
    raise AssertionError(f"{text!r} not in {path}")


def test_docker_stop_exits_zero_and_keeps_the_log(
    engine: Any, stub_image: str, tmp_path: Path
) -> None:
    container = _run(engine, stub_image, ["striker"], tmp_path / "logs")
    log = tmp_path / "logs" / "stub_blue_3.log"
    _wait_for(log, "not available")
    container.stop(timeout=20)
    assert container.wait(timeout=30)["StatusCode"] == 0
    assert "received SIGTERM" in log.read_text()


def test_ignore_sigterm_is_killed_after_the_grace_time(
    engine: Any, stub_image: str, tmp_path: Path
) -> None:
    container = _run(engine, stub_image, ["ignore-sigterm"], tmp_path / "logs")
    _wait_for(tmp_path / "logs" / "stub_blue_3.log", "ignoring SIGTERM")
    container.stop(timeout=2)
    container.reload()
    assert container.attrs["State"]["ExitCode"] == 137
    assert container.attrs["State"]["OOMKilled"] is False
