"""Names, addresses and container requests of one match (pure functions, no I/O).

Networks: one bridge per team (``<prefix>-red``, ``<prefix>-blue``, internal unless the game
allows the internet) and one internal control network. Each is a /24 from 10.213.0.0/16, chosen
at run time (a subnet in use is skipped). In every subnet: .1 the host's gateway, .2 the
simulator, .10+n robot n of the team.

Each robot is one container behind the start gate (:mod:`orchestrator.match.gate`: started
on its team's network with its fixed IP and hostname, shaped, then let run), or where the gate
cannot be built two: a *holder* that owns the robot's network namespace and runs nothing but
``sleep``, and the robot container itself, started in the holder's namespace
(``network_mode=container:<holder>``) once the bandwidth limits are in place.
"""

from __future__ import annotations

import hashlib
import ipaddress
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Protocol

from contracts import files
from orchestrator.config import Limits
from orchestrator.config.robot_models import container_path
from orchestrator.engine import (
    LABEL_MATCH,
    LABEL_PROJECT,
    LABEL_ROBOT,
    LABEL_ROLE,
    LABEL_TEAM,
)
from orchestrator.match.admission import SIMULATOR_CPU_SHARES
from orchestrator.match.gpu import SimulatorGpu
from orchestrator.match.plan import MatchPlan, RobotPlan
from orchestrator.runtime.port import (
    Attachment,
    BindMount,
    ContainerRequest,
    NetworkRequest,
)

SIMULATOR_HOST = 2
ROBOT_HOST_BASE = 10
TELEMETRY_PORT = 7447
NODE_NETNS_TARGET = "/node-net"  # where a node holder sees its node's network namespace
LABEL_NODE = "org.hlvs-runner.node"  # league placement: the node a holder stands for
LOGS_TARGET = "/robocup-logs"
# A robot's root file system is read-only; these folders of its capped scratch space are
# writable (sub-folder name in the scratch space -> path in the container).
SCRATCH_DIRS = {"tmp": "/tmp", "var-tmp": "/var/tmp", "root": "/root"}
SCRATCH_FALLBACK_TMPFS_BYTES = 256 * 1024 * 1024  # per folder, when no capped space can be made
RUN_TMPFS = "size=16m,mode=755"
# A robot's CPU limit is enforced over 10 ms periods (Docker's default is 100 ms): a robot that
# burns its share is held back in short slices, so the robots it shares CPUs with wait
# milliseconds, not tens of milliseconds, when they need a CPU.
ROBOT_CPU_PERIOD_US = 10_000
MATCH_TARGET = files.CONTAINER_MATCH_DIR
SIMULATOR_COMMAND = (
    "python3", "-m", "simulator", "run",
    "--spec", f"{MATCH_TARGET}/{files.MATCH_SPEC}", "--out", f"{MATCH_TARGET}/{files.OUT_DIR}",
)  # fmt: skip


def short_token(match_id: str, salt: str) -> str:
    return hashlib.sha256(f"{match_id}/{salt}".encode()).hexdigest()[:8]


def labels(match_id: str, role: str, **extra: str) -> dict[str, str]:
    found = {LABEL_PROJECT: "1", LABEL_MATCH: match_id, LABEL_ROLE: role}
    if "team" in extra:
        found[LABEL_TEAM] = extra["team"]
    if "robot" in extra:
        found[LABEL_ROBOT] = extra["robot"]
    for key, value in extra.items():
        if "." in key:
            found[key] = value
    return found


@dataclass(frozen=True, slots=True, kw_only=True)
class Subnet:
    network: ipaddress.IPv4Network

    def host(self, n: int) -> str:
        return str(self.network.network_address + n)

    @property
    def gateway(self) -> str:
        return self.host(1)

    @property
    def simulator(self) -> str:
        return self.host(SIMULATOR_HOST)

    def robot(self, number: int) -> str:
        return self.host(ROBOT_HOST_BASE + number)


def candidate_subnets(seed: str) -> list[Subnet]:
    """Every 10.213.x.0/24, starting at a place derived from ``seed``."""
    start = int(hashlib.sha256(seed.encode()).hexdigest(), 16) % 256
    return [
        Subnet(network=ipaddress.IPv4Network(f"10.213.{(start + i) % 256}.0/24"))
        for i in range(256)
    ]


def network_request(
    *, prefix: str, role: str, subnet: Subnet, internal: bool, match_id: str,
    extra_labels: Mapping[str, str],
) -> NetworkRequest:
    return NetworkRequest(
        name=f"{prefix}-{role}",
        subnet=str(subnet.network),
        gateway=subnet.gateway,
        internal=internal,
        bridge_name=f"hl{short_token(match_id, prefix)}{role[0]}",
        labels={**labels(match_id, "network", **({"team": role} if role != "control" else {})),
                **extra_labels},
    )


class TeamAddresses(Protocol):
    """Where a team's robots find the simulator and each other: a :class:`Subnet` (dense
    placement) or the nodes' addresses (:class:`orchestrator.match.placement.NodeAddresses`)."""

    @property
    def simulator(self) -> str: ...

    def robot(self, number: int) -> str: ...


def robot_environment(
    robot: RobotPlan, *, team_net: TeamAddresses, player_count: int,
    gamecontroller_ip: str | None,
) -> dict[str, str]:
    env = {
        "ROBOCUP_ROBOT_ID": str(robot.number),
        "ROBOCUP_TEAM_COLOR": robot.color,
        "ROBOCUP_SIMULATOR_ADDR": f"{team_net.simulator}:{robot.port}",
        "ROBOCUP_MIRROR_SERVER_IP": team_net.simulator,
    }
    if robot.team_id is not None:  # optional in the league; teams read it to find their team
        env["ROBOCUP_TEAM_ID"] = str(robot.team_id)  # in the GameController's packets
    for n in range(1, player_count + 1):
        env[f"ROBOCUP_TEAM_PLAYER{n}_IP"] = team_net.robot(n)
    if gamecontroller_ip is not None:
        env["ROBOCUP_GAMECONTROLLER_IP"] = gamecontroller_ip
    return env


def holder_request(
    robot: RobotPlan, *, prefix: str, image: str, network: str, team_net: Subnet, match_id: str,
    extra_labels: Mapping[str, str],
) -> ContainerRequest:
    return ContainerRequest(
        name=f"{prefix}-{robot.key}-net",
        image=image,
        entrypoint=("sleep",),
        command=("infinity",),
        labels={**labels(match_id, "netns", team=robot.color, robot=str(robot.number)),
                **extra_labels},
        networks=(Attachment(network=network, ipv4_address=team_net.robot(robot.number),
                             aliases=(robot.key,)),),
        hostname=robot.key,
        mem_bytes=32 * 1024 * 1024,
        pids_limit=8,
        cap_drop=("ALL",),
        security_opt=("no-new-privileges",),
    )


def node_holder_request(
    node: str, *, prefix: str, image: str, netns: str, match_id: str,
    extra_labels: Mapping[str, str],
) -> ContainerRequest:
    """League placement where nodes share one Docker engine: a container that joins the node's
    network namespace ``netns`` (``nsenter``, the one capability it needs) and sleeps; the
    simulator or robot container started in its network (``container:<holder>``) then has the
    node's network, as ``--network host`` gives it on the node's own machine."""
    return ContainerRequest(
        name=f"{prefix}-node-{node}",
        image=image,
        entrypoint=("nsenter",),
        command=(f"--net={NODE_NETNS_TARGET}", "sleep", "infinity"),
        labels={**labels(match_id, "netns", **{LABEL_NODE: node}), **extra_labels},
        mounts=(BindMount(source=Path(netns), target=NODE_NETNS_TARGET, read_only=True),),
        network_mode="none",
        mem_bytes=32 * 1024 * 1024,
        pids_limit=8,
        cap_drop=("ALL",),
        cap_add=("SYS_ADMIN",),
        security_opt=("no-new-privileges",),
    )


# what the engine keeps of one robot's stdout and stderr together (two rotated files of half),
# and what the match keeps of each stream (stdout.log, stderr.log); the rest is dropped and the
# cut is named in report.json
ROBOT_CONSOLE_BYTES = 32_000_000
# Under a runtime other than the engine's default (gVisor's runsc) the runtime's own host tasks
# live in the robot container's pids cgroup: runsc's sentry and gofer are 44 to 50 of them for an
# idle robot here, and each program the robot starts is one more (a ptrace stub process). A
# limit they do not fit makes the sandbox itself fail (runsc ends the robot with exit 2, "error
# initializing first thread: resource temporarily unavailable", at a program's start or end).
# The engine's limit is ``limits.pids`` plus this, so that ``limits.pids`` stays the robot's own.
SANDBOX_PIDS = 128


def robot_pids_limit(limits: Limits) -> int:
    """The engine's pids limit of a robot container: ``limits.pids``, plus the sandbox's own
    tasks (:data:`SANDBOX_PIDS`) where ``limits.robot_runtime`` names another runtime."""
    return limits.pids + (SANDBOX_PIDS if limits.robot_runtime else 0)


def robot_request(
    robot: RobotPlan, *, prefix: str, holder_id: str | None, environment: Mapping[str, str],
    logs_dir: Path, limits: Limits, match_id: str, extra_labels: Mapping[str, str],
    scratch_dir: Path | None = None, cgroup_parent: str | None = None,
) -> ContainerRequest:
    """``holder_id``: the holder whose network the robot joins (None: the caller gives the
    robot its network, behind the start gate: :mod:`orchestrator.match.gate`).
    ``scratch_dir``: the robot's capped scratch space (its :data:`SCRATCH_DIRS` are bound into
    the container); None: size-capped tmpfs folders instead (they count as memory)."""
    assert robot.image is not None
    scratch: tuple[BindMount, ...] = ()
    tmpfs = {"/run": RUN_TMPFS}
    if scratch_dir is not None:
        scratch = tuple(BindMount(source=scratch_dir / name, target=target)
                        for name, target in SCRATCH_DIRS.items())
    else:
        size = min(SCRATCH_FALLBACK_TMPFS_BYTES, int(limits.scratch_gb * 1e9))
        tmpfs.update({target: f"size={size}" for target in SCRATCH_DIRS.values()})
    return ContainerRequest(
        name=f"{prefix}-{robot.key}",
        image=robot.image,
        command=robot.command,
        environment=dict(environment),
        labels={**labels(match_id, "robot", team=robot.color, robot=str(robot.number)),
                **extra_labels},
        network_mode=f"container:{holder_id}" if holder_id is not None else None,
        mounts=(BindMount(source=logs_dir, target=LOGS_TARGET), *scratch),
        read_only=True,
        tmpfs=tmpfs,
        nano_cpus=int(limits.cpus * 1e9),
        cpu_period_us=ROBOT_CPU_PERIOD_US,
        mem_bytes=int(limits.memory_gb * 1e9),
        pids_limit=robot_pids_limit(limits),
        cap_drop=("ALL",),
        security_opt=("no-new-privileges",),
        cgroup_parent=cgroup_parent,
        console_max_bytes=ROBOT_CONSOLE_BYTES,
        runtime=limits.robot_runtime or None,
    )


def simulator_request(
    plan: MatchPlan, *, prefix: str, image: str, match_dir: Path,
    attachments: tuple[Attachment, ...], extra_labels: Mapping[str, str],
    command: tuple[str, ...] = SIMULATOR_COMMAND,
    model_dirs: tuple[Path, ...] = (),
    gpu: SimulatorGpu | None = None,
) -> ContainerRequest:
    """The simulator container; team robot model packages mounted read-only where the match
    spec names them (:func:`orchestrator.config.robot_models.container_path`); with ``gpu`` the
    host's NVIDIA GPUs and the environment that makes MuJoCo render through them."""
    models = tuple(
        BindMount(source=folder, target=container_path(str(folder)), read_only=True)
        for folder in model_dirs
    )
    return ContainerRequest(
        name=f"{prefix}-simulator",
        image=image,
        command=command,
        environment={"PYTHONUNBUFFERED": "1", "HLVS_MATCH_ID": plan.match_id,
                     **(gpu.environment() if gpu is not None else {})},
        labels={**labels(plan.match_id, "simulator"), **extra_labels},
        networks=attachments,
        mounts=(BindMount(source=match_dir, target=MATCH_TARGET), *models),
        hostname="simulator",
        cpu_shares=SIMULATOR_CPU_SHARES,
        cap_drop=("ALL",),
        security_opt=("no-new-privileges",),
        device_requests=gpu.device_requests() if gpu is not None else (),
    )


__all__ = [
    "LOGS_TARGET",
    "ROBOT_CONSOLE_BYTES",
    "SANDBOX_PIDS",
    "SCRATCH_DIRS",
    "SIMULATOR_COMMAND",
    "Subnet",
    "TELEMETRY_PORT",
    "TeamAddresses",
    "candidate_subnets",
    "holder_request",
    "labels",
    "network_request",
    "node_holder_request",
    "robot_environment",
    "robot_pids_limit",
    "robot_request",
    "short_token",
    "simulator_request",
]
