"""Fixtures for match integration tests: a real Docker engine, a small test image with a test
robot controller and a stand-in simulator, and a runner that cleans up by label."""

from __future__ import annotations

import hashlib
import io
import tarfile
import threading
import uuid
from collections.abc import Callable, Iterator, Mapping
from pathlib import Path
from typing import Any

import docker
import pytest

from contracts.match_spec import MatchSpec
from orchestrator.config import Limits
from orchestrator.errors import OrchestratorError
from orchestrator.match import (
    HostControl,
    MatchOutcome,
    MatchPlan,
    MatchRunner,
    RobotPlan,
    RunOptions,
    TeamPlan,
    cleanup,
    start_gate,
)
from orchestrator.runtime.port import ContainerRequest, NetworkInfo, NetworkRequest
from orchestrator.telemetry import ZenohTelemetry
from testkit.specs import match_spec
from tests.conftest import TEST_LABEL

ASSETS = Path(__file__).parent / "assets"
LOCAL_BASES = ("hlvs-runner/base:bookworm", "hlvs-runner-test/e-base:bookworm")


def _base_image(client: docker.DockerClient) -> str:
    try:
        from orchestrator.project_images import project_image  # type: ignore[attr-defined]

        return str(project_image("team-base"))
    except (ImportError, AttributeError, OrchestratorError):
        pass
    for name in LOCAL_BASES:
        try:
            client.images.get(name)
            return name
        except docker.errors.ImageNotFound:
            continue
    pytest.skip("no base image with python3 (run `hlvs images build`)")


@pytest.fixture(scope="session")
def runtime(docker_client: docker.DockerClient) -> Any:
    from orchestrator.engine.containers import DockerRuntime

    return DockerRuntime(docker_client)


@pytest.fixture(scope="session")
def test_image(docker_client: docker.DockerClient) -> str:
    base = _base_image(docker_client)
    files = {p.name: p.read_bytes() for p in sorted(ASSETS.glob("*.py"))}
    dockerfile = f"FROM {base}\nCOPY *.py /opt/t/\nCMD [\"python3\", \"/opt/t/robot.py\"]\n"
    digest = hashlib.sha256(dockerfile.encode())
    for name, data in files.items():
        digest.update(name.encode() + data)
    tag = f"hlvs-runner-test/match:{digest.hexdigest()[:12]}"
    try:
        docker_client.images.get(tag)
        return tag
    except docker.errors.ImageNotFound:
        pass
    buffer = io.BytesIO()
    with tarfile.open(fileobj=buffer, mode="w") as tar:
        for name, data in {**files, "Dockerfile": dockerfile.encode()}.items():
            info = tarfile.TarInfo(name)
            info.size = len(data)
            tar.addfile(info, io.BytesIO(data))
    buffer.seek(0)
    docker_client.images.build(fileobj=buffer, custom_context=True, tag=tag,
                               network_mode="none", labels={TEST_LABEL: "1"}, rm=True, forcerm=True)
    return tag


def spec_builder(match_id: str, red: list[RobotPlan], blue: list[RobotPlan]) -> Any:
    ports = {"red": {r.number: r.port for r in red}, "blue": {r.number: r.port for r in blue}}

    def build(addresses: Mapping[str, tuple[str, ...]], telemetry: str | None) -> MatchSpec:
        return match_spec(match_id=match_id, seed=7, ports=ports, addresses=addresses,
                          telemetry=telemetry)

    return build


def robots(color: str, image: str | None, commands: list[list[str] | None]) -> list[RobotPlan]:
    base = 10000 + (20 if color == "blue" else 0)
    return [
        RobotPlan(color=color, number=n, port=base + n, image=image,
                  command=("python3", "/opt/t/robot.py", *cmd) if cmd is not None else None)
        for n, cmd in enumerate(commands, start=1)
    ]


MatchFactory = Callable[..., MatchOutcome]


class _Told:
    """The engine, telling ``on_created`` of each network and container it has created (with
    the request it was made from), so that a test sees the match's objects as they come."""

    def __init__(self, runtime: Any,
                 on_created: Callable[[ContainerRequest | NetworkRequest], None]) -> None:
        self._runtime = runtime
        self._on_created = on_created

    def __getattr__(self, name: str) -> Any:
        return getattr(self._runtime, name)

    def create_network(self, request: NetworkRequest) -> NetworkInfo:
        info: NetworkInfo = self._runtime.create_network(request)
        self._on_created(request)
        return info

    def create_container(self, request: ContainerRequest) -> str:
        container_id: str = self._runtime.create_container(request)
        self._on_created(request)
        return container_id


@pytest.fixture
def play(runtime: Any, test_image: str, tmp_path: Path) -> Iterator[MatchFactory]:
    """``play(red=[cmd...], blue=[cmd...], sim=("3",), limits=..., ...) -> MatchOutcome``."""
    match_ids: list[str] = []
    host = HostControl()

    def factory(
        *, red: list[list[str] | None], blue: list[list[str] | None],
        sim: tuple[str, ...] = ("3",), limits: Limits | None = None, grace_s: float = 2.0,
        red_image: str | None = "", blue_image: str | None = "", out: Path | None = None,
        on_created: Callable[[ContainerRequest | NetworkRequest], None] | None = None,
        stop_event: threading.Event | None = None,
        telemetry_silence_s: float | None = None, holders: bool = False,
    ) -> MatchOutcome:
        match_id = f"t{uuid.uuid4().hex[:8]}"
        match_ids.append(match_id)
        red_plan = robots("red", test_image if red_image == "" else red_image, red)
        blue_plan = robots("blue", test_image if blue_image == "" else blue_image, blue)
        plan = MatchPlan(
            match_id=match_id, seed=7,
            red=TeamPlan(color="red", name="Red", robots=tuple(red_plan)),
            blue=TeamPlan(color="blue", name="Blue", robots=tuple(blue_plan)),
            spec_builder=spec_builder(match_id, red_plan, blue_plan),
            limits=limits or Limits(cpus=1.0, memory_gb=0.5, log_folder_gb=0.05),
            grace_period_s=grace_s, telemetry=telemetry_silence_s is not None,
            telemetry_silence_s=telemetry_silence_s or 30.0,
        )
        options = RunOptions(
            out_dir=out or tmp_path / match_id, simulator_image=test_image,
            simulator_command=("python3", "/opt/t/fakesim.py", *sim),
            extra_labels={TEST_LABEL: "1"}, poll_s=0.2,
            # as a match starts them: behind the start gate (``holders``: in holders' networks)
            start_gate=None if holders else start_gate(),
        )
        runner = MatchRunner(
            plan, runtime=runtime if on_created is None else _Told(runtime, on_created),
            host=host, options=options, stop_event=stop_event,
            telemetry=lambda endpoint, mid: ZenohTelemetry(endpoint=endpoint, match_id=mid),
        )
        return runner.run()

    yield factory
    for match_id in match_ids:
        cleanup(runtime, host, match_id=match_id)
