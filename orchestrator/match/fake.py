"""In-memory stand-ins for unit tests: :class:`FakeRuntime`, :class:`FakeHost`,
:class:`FakeTelemetry`. They keep what was asked of them so tests can assert on it."""

from __future__ import annotations

import itertools
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field, replace
from pathlib import Path

from contracts import EventRecord, SimResult, StateMessage, files
from orchestrator.bandwidth import AppliedShaping, RobotShaping, TrafficCounters
from orchestrator.errors import EngineLost
from orchestrator.match.logfs import LogFolder
from orchestrator.match.placement import NodeFirewall
from orchestrator.match.safecopy import CopyReport
from orchestrator.runtime.port import (
    ContainerRequest,
    ContainerState,
    NetworkInfo,
    NetworkRequest,
    ObjectNotFound,
    ProjectObject,
    StatsSample,
    SubnetInUse,
)


@dataclass(slots=True)
class FakeContainer:
    request: ContainerRequest
    state: ContainerState
    stops: list[float] = field(default_factory=list)
    console: dict[str, str] = field(default_factory=dict)  # "stdout" / "stderr" -> more text


class FakeRuntime:
    """Containers "run" until a test ends them with :meth:`exit`; the simulator can be told to
    write its result files and exit after ``simulator_polls`` inspections."""

    def __init__(self, *, busy_subnets: tuple[str, ...] = (), missing_images: tuple[str, ...] = (),
                 simulator_exit_code: int | None = 0, simulator_polls: int = 3,
                 sim_result: SimResult | None = None) -> None:
        self.networks: dict[str, NetworkRequest] = {}
        self.containers: dict[str, FakeContainer] = {}
        self.busy_subnets = set(busy_subnets)
        self.missing_images = set(missing_images)
        # each image's entry point and command (default ``/entrypoint.sh`` and ``run``)
        self.image_launches: dict[str, tuple[tuple[str, ...], tuple[str, ...]]] = {}
        self.simulator_exit_code = simulator_exit_code
        self.simulator_polls = simulator_polls
        self.sim_result = sim_result or SimResult(
            match_id="fake", seed=0, state="FINISHED", score={"red": 2, "blue": 1}, winner="red")
        self.calls: list[tuple[str, str]] = []
        self._ids = itertools.count(1)
        self.on_start: Callable[[FakeContainer], None] | None = None
        self.foreign: set[str] = set()  # started outside the runner (not in its records)
        self.down_for = 0  # the engine is down: this many more pings fail, every call raises

    def endpoint(self) -> str:
        return "fake://engine"

    def answering(self) -> bool:
        if self.down_for > 0:
            self.down_for -= 1
            return False
        return True

    def restart_engine(self, *, down_for_pings: int) -> None:
        """The engine stops every container (its stop: code 137) and stops answering until
        ``down_for_pings`` pings have failed; the containers and networks stay, exited."""
        for container_id, found in self.containers.items():
            if found.state.running:
                self.exit(container_id, 137)
        self.down_for = down_for_pings

    def _answer(self, doing: str) -> None:
        if self.down_for > 0:
            raise EngineLost(endpoint=self.endpoint(), doing=doing,
                             reason="('Connection aborted.', FileNotFoundError(2))")

    def create_network(self, request: NetworkRequest) -> NetworkInfo:
        self.calls.append(("create_network", request.name))
        if request.subnet in self.busy_subnets:
            raise SubnetInUse(subnet=request.subnet, reason="Pool overlaps")
        self.networks[request.name] = request
        return NetworkInfo(id=f"net{len(self.networks)}", name=request.name,
                           subnet=request.subnet, gateway=request.gateway,
                           bridge_name=request.bridge_name)

    def remove_network(self, name: str) -> None:
        self.calls.append(("remove_network", name))
        self._answer(f"network {name}")
        found = [n for n, r in self.networks.items() if n == name]
        if not found:
            raise ObjectNotFound(kind="network", name=name)
        del self.networks[found[0]]

    def create_container(self, request: ContainerRequest) -> str:
        self.calls.append(("create_container", request.name))
        container_id = f"c{next(self._ids)}"
        self.containers[container_id] = FakeContainer(
            request=request,
            state=ContainerState(id=container_id, name=request.name, status="created",
                                 running=False, exit_code=None, oom_killed=False,
                                 restart_count=0, pid=0),
        )
        return container_id

    def _get(self, container_id: str) -> FakeContainer:
        self._answer(f"container {container_id}")
        if container_id not in self.containers:
            raise ObjectNotFound(kind="container", name=container_id)
        return self.containers[container_id]

    def start(self, container_id: str) -> None:
        self.calls.append(("start", container_id))
        found = self._get(container_id)
        found.state = replace(found.state, status="running", running=True,
                              pid=1000 + int(container_id[1:]))  # one per container
        if self.on_start is not None:
            self.on_start(found)

    def exit(self, container_id: str, code: int, *, oom: bool = False) -> None:
        found = self._get(container_id)
        found.state = replace(found.state, status="exited", running=False, exit_code=code,
                              oom_killed=oom, pid=0)

    def stop(self, container_id: str, *, timeout_s: float) -> None:
        self.calls.append(("stop", container_id))
        found = self._get(container_id)
        found.stops.append(timeout_s)
        if found.state.running:
            self.exit(container_id, 0)

    def kill(self, container_id: str) -> None:
        self.calls.append(("kill", container_id))
        if self._get(container_id).state.running:
            self.exit(container_id, 137)

    def remove(self, container_id: str) -> None:
        self.calls.append(("remove", container_id))
        self._get(container_id)
        del self.containers[container_id]

    def inspect(self, container_id: str) -> ContainerState:
        found = self._get(container_id)
        role = found.request.labels.get("org.hlvs-runner.role")
        if role == "simulator" and found.state.running and self.simulator_exit_code is not None:
            self.simulator_polls -= 1
            if self.simulator_polls <= 0:
                self._finish_simulator(found)
        return found.state

    def _finish_simulator(self, found: FakeContainer) -> None:
        mount = found.request.mounts[0].source
        out = Path(mount) / files.OUT_DIR
        out.mkdir(parents=True, exist_ok=True)
        if self.simulator_exit_code == 0:
            self.sim_result.write(out / files.SIM_RESULT)
            (out / files.REPLAY).write_text("replay")
        assert self.simulator_exit_code is not None
        self.exit(found.state.id, self.simulator_exit_code)

    def wait(self, container_id: str, *, timeout_s: float) -> int | None:
        return self._get(container_id).state.exit_code

    def stats_stream(self, container_id: str) -> Iterator[StatsSample]:
        yield StatsSample(cpu_percent=50.0, memory_bytes=1000)
        yield StatsSample(cpu_percent=150.0, memory_bytes=4000)

    def save_logs(self, container_id: str, *, stdout: Path, stderr: Path,
                  max_bytes: int | None = None) -> tuple[str, ...]:
        found = self._get(container_id)
        cut = []
        for path in (stdout, stderr):
            path.parent.mkdir(parents=True, exist_ok=True)
            text = f"{found.request.name} {path.stem}\n" + found.console.get(path.stem, "")
            if max_bytes is not None and len(text) > max_bytes:
                text = text[:max_bytes]
                cut.append(path.stem)
            path.write_text(text)
        return tuple(cut)

    def copy_out(self, container_id: str, path: str, destination: Path) -> None:
        self._get(container_id)
        destination.mkdir(parents=True, exist_ok=True)
        (destination / Path(path).name).write_text(f"copied from {container_id}:{path}\n")

    def image_digest(self, image: str) -> str | None:
        return None if image in self.missing_images else f"sha256:{abs(hash(image)):x}"

    def image_launch(self, image: str) -> tuple[tuple[str, ...], tuple[str, ...]]:
        self._answer(f"image {image}")
        if image in self.missing_images:
            raise ObjectNotFound(kind="image", name=image)
        for name, launch in self.image_launches.items():  # by name or by digest
            if image in (name, self.image_digest(name)):
                return launch
        return ("/entrypoint.sh",), ("run",)

    def list_project(self, *, match_id: str | None = None) -> list[ProjectObject]:
        self._answer("containers labelled")
        found = [ProjectObject(kind="container", id=cid, name=c.request.name,
                               labels=c.request.labels, created=cid not in self.foreign)
                 for cid, c in self.containers.items()]
        found += [ProjectObject(kind="network", id=name, name=name, labels=r.labels)
                  for name, r in self.networks.items()]
        if match_id is None:
            return found
        return [o for o in found if o.labels.get("org.hlvs-runner.match") == match_id]


@dataclass(slots=True)
class FakeHost:
    isolated: list[str] = field(default_factory=list)
    shaped: list[RobotShaping] = field(default_factory=list)
    folders: list[Path] = field(default_factory=list)
    released: list[str] = field(default_factory=list)
    released_folders: list[Path] = field(default_factory=list)
    node_firewalls: dict[str, NodeFirewall] = field(default_factory=dict)  # netns -> rules
    unshaped: list[str] = field(default_factory=list)

    def isolate_bridge(self, bridge_name: str, *, match_id: str) -> bool:
        self.isolated.append(bridge_name)
        return True

    def remove_isolation(self, *, match_id: str | None) -> int:
        removed = len(self.isolated)
        self.released.append(str(match_id))
        self.isolated.clear()
        return removed

    def shape(self, pid: int, shaping: RobotShaping) -> AppliedShaping | None:
        self.shaped.append(shaping)
        return AppliedShaping(netns=f"/proc/{pid}/ns/net", device="eth0", host_ifindex=7,
                              api_rate_bit=shaping.api_rate_bit,
                              comm_rate_bit=shaping.comm_rate_bit, applied_ms=1.0)

    def shape_node(self, netns: str, shaping: RobotShaping) -> AppliedShaping | None:
        self.shaped.append(shaping)
        return AppliedShaping(netns=netns, device="eth0", host_ifindex=7,
                              api_rate_bit=shaping.api_rate_bit,
                              comm_rate_bit=shaping.comm_rate_bit, applied_ms=1.0)

    def unshape(self, applied: AppliedShaping) -> None:
        self.unshaped.append(applied.netns)

    def node_firewall(self, netns: str | None, firewall: NodeFirewall) -> bool:
        self.node_firewalls[str(netns)] = firewall
        return True

    def remove_node_firewall(self, netns: str | None) -> None:
        self.node_firewalls.pop(str(netns), None)

    def in_netns(self, pid: int, netns: str) -> bool:
        return True

    def counters(self, applied: AppliedShaping) -> TrafficCounters:
        return TrafficCounters(sent_api_bytes=100, sent_comm_bytes=10, received_api_bytes=200,
                               received_comm_bytes=20)

    def log_folder(self, *, match_id: str, name: str, cap_bytes: int, fallback: Path
                   ) -> LogFolder:
        fallback.mkdir(parents=True, exist_ok=True)
        self.folders.append(fallback)
        return LogFolder(path=fallback, cap_bytes=cap_bytes)

    def release(self, folder: LogFolder) -> None:
        self.released_folders.append(folder.path)

    def collect_logs(self, folder: LogFolder, destination: Path, *,
                     limit_bytes: int | None = None) -> CopyReport:
        destination.mkdir(parents=True, exist_ok=True)
        return CopyReport()

    def cleanup(self, *, match_id: str | None) -> int:
        return self.remove_isolation(match_id=match_id)


class FakeTelemetry:
    """A telemetry source a test feeds by hand (``states`` are served one per ``latest``)."""

    def __init__(self, states: list[StateMessage], *, clock: Callable[[], float],
                 silent: bool = False) -> None:
        self._states = list(states)
        self._clock = clock
        self._silent = silent
        self._last: StateMessage | None = None
        self.closed = False

    def latest(self) -> StateMessage | None:
        if self._states and not self._silent:
            self._last = self._states.pop(0)
        return self._last

    def last_message_at(self) -> float | None:
        return None if self._silent else self._clock()

    def events(self) -> list[EventRecord]:
        return []

    def close(self) -> None:
        self.closed = True


__all__ = ["FakeContainer", "FakeHost", "FakeRuntime", "FakeTelemetry"]
