"""The simulator's GPU: detection on the host (fake device files, engine info, hook, CDI specs),
the auto / on / off decision, and what the simulator container is asked for."""

from __future__ import annotations

import json
import logging
from dataclasses import replace
from pathlib import Path
from typing import Any

import docker
import pytest

from orchestrator.engine.containers import DockerRuntime
from orchestrator.engine.gpu import CONTROL_DEVICE, detect, detect_nvidia
from orchestrator.errors import ConfigError
from orchestrator.match import MatchRunner, RunOptions
from orchestrator.match.fake import FakeHost, FakeRuntime
from orchestrator.match.gpu import GpuDetection, GpuOrigin, SimulatorGpu, simulator_gpu
from orchestrator.match.layout import simulator_request
from orchestrator.runtime.port import ContainerRequest, DeviceRequest
from tests.unit.match.test_match_runner import _plan

GPU_FILES = ("/dev/nvidia0", CONTROL_DEVICE)


def _detect(info: dict[str, Any] | None, *, files: tuple[str, ...] = GPU_FILES,
            hook: str | None = None, specs: tuple[str, ...] = (), error: str = ""
            ) -> GpuDetection:
    return detect(info, devices=lambda: files, which=lambda name: hook,
                  cdi_specs=lambda dirs: specs, info_error=error)


# detection ----------------------------------------------------------------------------------
def test_no_device_file_means_no_gpu_whatever_the_engine_says() -> None:
    found = _detect({"Runtimes": {"nvidia": {}}}, files=())
    assert found.access is None and not found.usable
    assert "no NVIDIA device file" in found.reason


def test_a_device_without_the_control_device_is_not_usable() -> None:
    found = _detect({"Runtimes": {"nvidia": {}}}, files=("/dev/nvidia0",))
    assert found.access is None and CONTROL_DEVICE in found.reason


def test_the_nvidia_runtime_of_the_engine_makes_it_usable() -> None:
    found = _detect({"Runtimes": {"runc": {}, "nvidia": {"path": "nvidia-container-runtime"}}})
    assert found.access == "device-request" and found.devices == GPU_FILES
    assert "nvidia runtime" in found.via


def test_the_toolkit_hook_on_the_path_makes_it_usable() -> None:
    found = _detect({"Runtimes": {"runc": {}}}, hook="/usr/bin/nvidia-container-runtime-hook")
    assert found.access == "device-request" and found.via.endswith("runtime-hook")


def test_a_cdi_spec_of_nvidia_gpus_makes_it_usable(tmp_path: Path) -> None:
    (tmp_path / "other.yaml").write_text("cdiVersion: 0.5.0\nkind: vendor.com/fpga\n")
    (tmp_path / "nvidia.yaml").write_text("cdiVersion: 0.5.0\nkind: nvidia.com/gpu\n")
    found = detect({"Runtimes": {"runc": {}}, "CDISpecDirs": [str(tmp_path)]},
                   devices=lambda: GPU_FILES, which=lambda name: None)
    assert found.access == "cdi" and found.via == f"CDI spec {tmp_path / 'nvidia.yaml'}"


def test_a_gpu_the_engine_cannot_hand_over_says_what_is_missing() -> None:
    found = _detect({"Runtimes": {"runc": {}}})
    assert found.access is None
    assert "/dev/nvidia0 present" in found.reason and "runtimes runc" in found.reason
    assert "NVIDIA container toolkit" in found.reason


def test_the_engine_is_asked_only_with_a_gpu_and_its_failure_is_the_reason() -> None:
    asked: list[int] = []

    class Engine:
        def __init__(self, info: dict[str, Any] | None) -> None:
            self._info = info

        def info(self) -> dict[str, Any]:
            asked.append(1)
            if self._info is None:
                raise docker.errors.DockerException("connection refused")
            return self._info

    assert detect_nvidia(Engine({}), devices=lambda: ()).access is None and asked == []
    broken = detect_nvidia(Engine(None), devices=lambda: GPU_FILES)
    assert broken.access is None and asked == [1]
    assert broken.reason == "the Docker engine did not answer: connection refused"
    found = detect_nvidia(Engine({"Runtimes": {"nvidia": {}}}), devices=lambda: GPU_FILES)
    assert found.access == "device-request"


# the decision ---------------------------------------------------------------------------------
def _probe(found: GpuDetection, calls: list[int]) -> Any:
    def probe() -> GpuDetection:
        calls.append(1)
        return found

    return probe


NONE = GpuDetection(access=None, reason="no NVIDIA device file (/dev/nvidia0, ...) on this host")
ONE = GpuDetection(access="device-request", devices=GPU_FILES, via="the engine's nvidia runtime")


def test_off_does_not_look_at_the_host() -> None:
    calls: list[int] = []
    assert simulator_gpu("off", _probe(ONE, calls)) is None
    assert calls == []


def test_on_without_a_gpu_is_an_error_naming_the_option(tmp_path: Path) -> None:
    origin = GpuOrigin(file=str(tmp_path / "game.json"), pointer="/gpu")
    with pytest.raises(ConfigError) as caught:
        simulator_gpu("on", _probe(NONE, []), origin=origin)
    text = str(caught.value)
    assert text.startswith(f'{tmp_path / "game.json"}: /gpu: "on" but no NVIDIA GPU')
    assert "no NVIDIA device file" in text and '"auto"' in text and '"off"' in text
    assert caught.value.exit_code == 2
    with pytest.raises(ConfigError, match="command line: --gpu"):
        simulator_gpu("on", _probe(NONE, []), origin=GpuOrigin(file="command line",
                                                               pointer="--gpu"))


def test_auto_without_a_gpu_falls_back_to_the_cpu_and_says_so_once(
    caplog: pytest.LogCaptureFixture,
) -> None:
    reason = GpuDetection(access=None, reason="a reason only this test gives")
    with caplog.at_level(logging.INFO, logger="orchestrator.match.gpu"):
        assert simulator_gpu("auto", _probe(reason, [])) is None
        assert simulator_gpu("auto", _probe(reason, [])) is None
    said = [r.getMessage() for r in caplog.records if "a reason only this test" in r.getMessage()]
    assert said == ["gpu auto: a reason only this test gives; the simulator renders cameras on "
                    "the CPU (OSMesa)"]


@pytest.mark.parametrize("mode", ["auto", "on"])
def test_a_usable_gpu_is_granted(mode: str) -> None:
    grant = simulator_gpu(mode, _probe(ONE, []))
    assert grant == SimulatorGpu(mode=mode, access="device-request",  # type: ignore[arg-type]
                                 devices=GPU_FILES)


def test_an_unknown_mode_is_refused() -> None:
    with pytest.raises(ConfigError, match='unknown value \'yes\' .*expected "auto" or "on" or '
                       '"off"'):
        simulator_gpu("yes", _probe(ONE, []))


# the simulator container ---------------------------------------------------------------------
def _request(gpu: SimulatorGpu | None, tmp_path: Path) -> ContainerRequest:
    return simulator_request(_plan(), prefix="hlvs-u1", image="sim:1", match_dir=tmp_path,
                             attachments=(), extra_labels={}, gpu=gpu)


def test_the_simulator_gets_every_gpu_graphics_and_egl(tmp_path: Path) -> None:
    request = _request(SimulatorGpu(mode="auto", access="device-request"), tmp_path)
    assert request.device_requests == (DeviceRequest(count=-1, capabilities=(("gpu",),)),)
    env = request.environment
    assert "graphics" in env["NVIDIA_DRIVER_CAPABILITIES"].split(",")
    assert env["NVIDIA_VISIBLE_DEVICES"] == "all"
    assert env["MUJOCO_GL"] == "egl" and env["PYOPENGL_PLATFORM"] == "egl"
    assert env["MUJOCO_EGL_DEVICE_ID"] == "0" and env["HLVS_GPU"] == "auto"
    assert env["HLVS_MATCH_ID"] == "u1"
    cdi = _request(SimulatorGpu(mode="on", access="cdi"), tmp_path)
    assert cdi.device_requests == (DeviceRequest(driver="cdi", device_ids=("nvidia.com/gpu=all",)),)
    assert cdi.environment["HLVS_GPU"] == "on"


def test_without_a_gpu_the_simulator_gets_nothing_of_it(tmp_path: Path) -> None:
    request = _request(None, tmp_path)
    assert request.device_requests == ()
    assert not {"MUJOCO_GL", "HLVS_GPU", "NVIDIA_VISIBLE_DEVICES", "MUJOCO_EGL_DEVICE_ID"} & set(
        request.environment)


def test_the_runner_starts_the_simulator_with_the_granted_gpu(tmp_path: Path) -> None:
    runtime = FakeRuntime()
    seen: list[ContainerRequest] = []
    runtime.on_start = lambda c: seen.append(c.request)
    grant = SimulatorGpu(mode="auto", access="device-request")
    runner = MatchRunner(_plan(), runtime=runtime, host=FakeHost(),
                         options=RunOptions(out_dir=tmp_path, simulator_image="sim:1",
                                            poll_s=0.0, gpu=grant))
    assert runner.run().ok
    simulator = next(r for r in seen if r.name == "hlvs-u1-simulator")
    assert simulator.device_requests == grant.device_requests()
    assert simulator.environment["MUJOCO_GL"] == "egl"
    robots = [r for r in seen if r.name.startswith("hlvs-u1-red-")]
    assert robots and all(r.device_requests == () for r in robots)


def test_docker_receives_the_device_request(tmp_path: Path) -> None:
    """The Docker SDK's own host config (API 1.41, as this engine) carries the request."""

    class Api(docker.APIClient):  # type: ignore[misc]
        created: dict[str, Any] = {}

        def create_container(self, **kwargs: Any) -> dict[str, str]:
            Api.created = kwargs
            return {"Id": "c1"}

    class Client:
        api = Api(base_url="unix:///nonexistent.sock", version="1.41")

    request = replace(_request(SimulatorGpu(mode="on", access="device-request"), tmp_path),
                      networks=())
    assert DockerRuntime(Client()).create_container(request) == "c1"
    host_config = Api.created["host_config"]
    assert host_config["DeviceRequests"] == [
        {"Driver": "", "Count": -1, "DeviceIDs": [], "Capabilities": [["gpu"]], "Options": {}}]
    assert Api.created["environment"]["MUJOCO_GL"] == "egl"
    plain = replace(_request(None, tmp_path), networks=())
    DockerRuntime(Client()).create_container(plain)
    assert "DeviceRequests" not in Api.created["host_config"]


# configuration and command line ---------------------------------------------------------------
def _game(tmp_path: Path, **extra: Any) -> Path:
    from tests.unit.config.conftest import GameFiles, valid_game, valid_team

    files = GameFiles(tmp_path, {**valid_game(), **extra}, valid_team(), valid_team())
    return files.write()


def test_game_json_gpu_reaches_the_plan_with_where_it_was_written(tmp_path: Path) -> None:
    from orchestrator.config import load_game
    from orchestrator.match import plan_from_game

    plan = plan_from_game(load_game(_game(tmp_path, gpu="on")))
    assert plan.gpu == "on"
    assert plan.gpu_origin == GpuOrigin(file=str(tmp_path / "game.json"), pointer="/gpu")
    assert plan_from_game(load_game(_game(tmp_path))).gpu == "auto"  # the league's files


def test_game_json_with_a_bad_gpu_value_names_the_field(tmp_path: Path) -> None:
    from orchestrator.config import load_game

    with pytest.raises(ConfigError) as caught:
        load_game(_game(tmp_path, gpu="yes"))
    assert any(p.pointer == "/gpu" for p in caught.value.problems), str(caught.value)


def test_the_command_line_overrides_game_json(tmp_path: Path) -> None:
    import argparse

    from hlvs.commands.play import _gpu_option
    from orchestrator.config import load_game
    from orchestrator.match import plan_from_game

    plan = plan_from_game(load_game(_game(tmp_path, gpu="on")))
    assert _gpu_option(argparse.Namespace(gpu=None), plan) is plan
    off = _gpu_option(argparse.Namespace(gpu="off"), plan)
    assert off.gpu == "off" and off.gpu_origin == GpuOrigin(file="command line", pointer="--gpu")


def test_hlvs_match_and_scrimmage_take_gpu(tmp_path: Path,
                                           capsys: pytest.CaptureFixture[str]) -> None:
    from hlvs.cli import build_parser
    from orchestrator.match.scrimmage import ScrimmageRequest, game_file

    parser = build_parser()
    assert parser.parse_args(["match", "g.json", "--gpu", "on"]).gpu == "on"
    assert parser.parse_args(["match", "g.json"]).gpu is None  # game.json decides
    scrim = parser.parse_args(["scrimmage", "--gpu", "off"])
    assert game_file(ScrimmageRequest.from_options(scrim), "m")["gpu"] == "off"
    default = ScrimmageRequest.from_options(parser.parse_args(["scrimmage"]))
    assert game_file(default, "m")["gpu"] == "auto"
    with pytest.raises(SystemExit):
        parser.parse_args(["scrimmage", "--gpu", "maybe"])
    assert "invalid choice: 'maybe'" in capsys.readouterr().err


def test_compose_asks_for_the_gpu_only_when_on(tmp_path: Path) -> None:
    from orchestrator.compose import _service

    service = _service(_request(SimulatorGpu(mode="on", access="device-request"), tmp_path), {})
    assert service["deploy"] == {"resources": {"reservations": {"devices": [
        {"count": "all", "capabilities": ["gpu"]}]}}}
    assert "deploy" not in _service(_request(None, tmp_path), {})
    json.dumps(service)  # plain data for the YAML file


def _refusing_gpu(tmp_path: Path, mode: str) -> tuple[Any, list[ContainerRequest], FakeRuntime]:
    from orchestrator.errors import InfrastructureError

    runtime = FakeRuntime()
    seen: list[ContainerRequest] = []

    def start(container: Any) -> None:
        seen.append(container.request)
        if container.request.device_requests:
            raise InfrastructureError('Docker engine refused on container c1: could not select '
                                      'device driver "" with capabilities: [[gpu]]')

    runtime.on_start = start
    grant = SimulatorGpu(mode=mode, access="device-request")  # type: ignore[arg-type]
    runner = MatchRunner(_plan(), runtime=runtime, host=FakeHost(),
                         options=RunOptions(out_dir=tmp_path, simulator_image="sim:1",
                                            poll_s=0.0, gpu=grant))
    return runner.run(), seen, runtime


def test_auto_falls_back_to_the_cpu_when_the_engine_refuses_the_gpu(
    tmp_path: Path, caplog: pytest.LogCaptureFixture,
) -> None:
    with caplog.at_level(logging.WARNING, logger="orchestrator.match.startup"):
        outcome, seen, runtime = _refusing_gpu(tmp_path, "auto")
    assert outcome.ok
    simulators = [r for r in seen if r.name == "hlvs-u1-simulator"]
    assert [bool(r.device_requests) for r in simulators] == [True, False]
    assert "MUJOCO_GL" not in simulators[1].environment
    assert simulators[1].environment["HLVS_MATCH_ID"] == "u1"
    assert any("refused the simulator the GPU" in r.getMessage()
               and "could not select device driver" in r.getMessage() for r in caplog.records)
    assert runtime.containers == {}  # the refused container was removed too


def test_on_fails_the_match_when_the_engine_refuses_the_gpu(tmp_path: Path) -> None:
    outcome, seen, runtime = _refusing_gpu(tmp_path, "on")
    assert outcome.failure is not None
    assert "could not select device driver" in outcome.failure.cause
    assert [r.name for r in seen].count("hlvs-u1-simulator") == 1
    assert runtime.containers == {}
