"""The container runtime boundary: what the match runner asks of a container engine, and what
the engine finds on the host (:class:`GpuDetection`).

The real implementation is :class:`orchestrator.engine.containers.DockerRuntime` (the only code
that imports ``docker``); :class:`orchestrator.match.fake.FakeRuntime` stands in for unit tests.
Every method raises :class:`orchestrator.errors.InfrastructureError` (or a subclass) when the
engine fails; ``NotFound`` is reported as :class:`ObjectNotFound`.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Literal, Protocol

from orchestrator.errors import InfrastructureError


class ObjectNotFound(InfrastructureError):
    """A container or network the runner refers to does not exist (any more)."""

    def __init__(self, *, kind: str, name: str, detail: str = "") -> None:
        self.kind = kind
        self.name = name
        self.detail = detail
        super().__init__(f"{kind} {name}: not found" + (f" ({detail})" if detail else ""))


class SubnetInUse(InfrastructureError):
    """The requested subnet overlaps a network that already exists; pick another one."""

    def __init__(self, *, subnet: str, reason: str) -> None:
        self.subnet = subnet
        self.reason = reason
        super().__init__(f"subnet {subnet} is in use: {reason}")


@dataclass(frozen=True, slots=True, kw_only=True)
class NetworkRequest:
    name: str
    subnet: str  # e.g. "10.213.4.0/24"
    gateway: str  # e.g. "10.213.4.1"
    internal: bool
    bridge_name: str  # host interface name (at most 15 characters)
    labels: Mapping[str, str] = field(default_factory=dict)


@dataclass(frozen=True, slots=True, kw_only=True)
class NetworkInfo:
    id: str
    name: str
    subnet: str
    gateway: str
    bridge_name: str


@dataclass(frozen=True, slots=True, kw_only=True)
class Attachment:
    network: str  # network name
    ipv4_address: str
    aliases: tuple[str, ...] = ()


@dataclass(frozen=True, slots=True, kw_only=True)
class BindMount:
    source: Path  # on the host, absolute (Docker takes a relative source for a volume name)
    target: str  # in the container
    read_only: bool = False

    def __post_init__(self) -> None:
        if not self.source.is_absolute():
            raise ValueError(f"bind-mount source must be absolute, got {self.source}")


@dataclass(frozen=True, slots=True, kw_only=True)
class DeviceRequest:
    """Devices of a driver for a container, as ``docker run --gpus``: ``count`` -1 is all of
    them; ``capabilities`` alternatives (each a set the driver must offer, e.g. ``gpu``);
    ``device_ids`` names them instead (a CDI device such as ``nvidia.com/gpu=all``)."""

    driver: str = ""  # "": the engine picks the driver offering the capabilities
    count: int = 0
    device_ids: tuple[str, ...] = ()
    capabilities: tuple[tuple[str, ...], ...] = ()


@dataclass(frozen=True, slots=True, kw_only=True)
class ContainerRequest:
    """Everything needed to create one container. ``network_mode`` ("container:<id>") excludes
    ``networks``; the first attachment is made at creation, the others before start."""

    name: str
    image: str
    command: tuple[str, ...] | None = None  # None: the image's default
    entrypoint: tuple[str, ...] | None = None
    environment: Mapping[str, str] = field(default_factory=dict)
    labels: Mapping[str, str] = field(default_factory=dict)
    networks: tuple[Attachment, ...] = ()
    network_mode: str | None = None
    mounts: tuple[BindMount, ...] = ()
    hostname: str | None = None
    nano_cpus: int | None = None
    mem_bytes: int | None = None  # memory and memory+swap (no swap)
    pids_limit: int | None = None
    cap_drop: tuple[str, ...] = ()
    cap_add: tuple[str, ...] = ()
    security_opt: tuple[str, ...] = ()
    working_dir: str | None = None
    read_only: bool = False  # read-only root file system
    cpu_shares: int | None = None  # CFS weight (Docker's default 1024)
    cpu_period_us: int | None = None  # CFS period for nano_cpus (Docker's default 100 ms)
    cpuset_cpus: str | None = None  # e.g. "1-3": the CPUs it may run on
    tmpfs: Mapping[str, str] = field(default_factory=dict)  # path -> mount options ("size=16m")
    cgroup_parent: str | None = None  # e.g. "/hlvs-robots" (a node firewall matches it)
    device_requests: tuple[DeviceRequest, ...] = ()  # e.g. the host's GPUs
    # the engine keeps at most this much of stdout and stderr together (two rotated files of
    # half of it); None: the engine's default (no cap)
    console_max_bytes: int | None = None
    runtime: str | None = None  # the engine's OCI runtime by name (e.g. "runsc"); None: default


@dataclass(frozen=True, slots=True, kw_only=True)
class ContainerState:
    id: str
    name: str
    status: str  # created, running, paused, restarting, exited, dead
    running: bool
    exit_code: int | None  # None while it has not run to an end
    oom_killed: bool
    restart_count: int
    pid: int  # 0 when not running
    error: str = ""
    started_at: str = ""
    finished_at: str = ""

    @property
    def exited(self) -> bool:
        return self.status in ("exited", "dead")


@dataclass(frozen=True, slots=True, kw_only=True)
class StatsSample:
    cpu_percent: float  # 100 = one full core
    memory_bytes: int


@dataclass(frozen=True, slots=True, kw_only=True)
class ProjectObject:
    """A container or network found by its project label (for cleanup)."""

    kind: str  # "container" | "network"
    id: str
    name: str
    labels: Mapping[str, str]
    created: bool = True  # in this runner's records (:mod:`orchestrator.runtime.ledger`)


class ContainerRuntime(Protocol):
    def endpoint(self) -> str: ...  # where the engine is, for messages

    def answering(self) -> bool: ...  # whether the engine answers now

    def create_network(self, request: NetworkRequest) -> NetworkInfo: ...

    def remove_network(self, name: str) -> None: ...

    def create_container(self, request: ContainerRequest) -> str: ...

    def start(self, container_id: str) -> None: ...

    def stop(self, container_id: str, *, timeout_s: float) -> None: ...

    def kill(self, container_id: str) -> None: ...

    def remove(self, container_id: str) -> None: ...

    def inspect(self, container_id: str) -> ContainerState: ...

    def wait(self, container_id: str, *, timeout_s: float) -> int | None: ...

    def stats_stream(self, container_id: str) -> Iterator[StatsSample]: ...

    def save_logs(self, container_id: str, *, stdout: Path, stderr: Path,
                  max_bytes: int | None = None) -> tuple[str, ...]: ...

    def copy_out(self, container_id: str, path: str, destination: Path) -> None: ...

    def image_digest(self, image: str) -> str | None: ...

    # the image's entry point and command, as the engine would run them (the robots' start gate
    # runs them itself); raises when the image is not present
    def image_launch(self, image: str) -> tuple[tuple[str, ...], tuple[str, ...]]: ...

    def list_project(self, *, match_id: str | None = None) -> list[ProjectObject]: ...


Access = Literal["device-request", "cdi"]


@dataclass(frozen=True, slots=True, kw_only=True)
class GpuDetection:
    """What the host offers (:func:`orchestrator.engine.detect_nvidia`): ``access`` is how
    Docker hands the GPU to a container (None: it cannot, ``reason`` says why), ``devices``
    the NVIDIA device files found."""

    access: Access | None
    devices: tuple[str, ...] = ()
    reason: str = ""
    via: str = ""  # what made the engine able to do it ("the nvidia runtime", "CDI spec ...")

    @property
    def usable(self) -> bool:
        return self.access is not None


GpuProbe = Callable[[], GpuDetection]


ROBOT_CGROUP = "hlvs-robots"  # robot containers' parent cgroup, relative to the cgroup v2 root
ROBOT_CGROUP_PARENT = f"/{ROBOT_CGROUP}"  # as Docker's --cgroup-parent (cgroupfs driver)


@dataclass(frozen=True, slots=True, kw_only=True)
class NodeFirewall:
    """What the robot processes on a robot node may reach: their own API port, the mirror and
    the GameController's return port on the simulator node, and the teammates' nodes; anything
    from the opponents' nodes is refused on the way in."""

    simulator: str
    api_port: int
    udp_ports: tuple[int, ...]  # on the simulator node: mirror, GameController return
    teammates: tuple[str, ...]
    opponents: tuple[str, ...]


__all__ = [
    "ROBOT_CGROUP",
    "ROBOT_CGROUP_PARENT",
    "Access",
    "Attachment",
    "BindMount",
    "ContainerRequest",
    "ContainerRuntime",
    "ContainerState",
    "DeviceRequest",
    "GpuDetection",
    "GpuProbe",
    "NetworkInfo",
    "NetworkRequest",
    "NodeFirewall",
    "ObjectNotFound",
    "ProjectObject",
    "StatsSample",
    "SubnetInUse",
]
