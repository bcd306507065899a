"""STARTING: networks, host firewall, match spec, simulator, then the robots in parallel.

:func:`start` takes the match's dependencies (:class:`~orchestrator.match.deps.MatchDeps`),
the ledger of what it creates (:class:`Created`) and the robots' records, and returns a
:class:`StartedMatch`: what runs, the telemetry, the bring-up breakdown and the failure, if no
robot of a team could be started. The ledger and the records are the caller's and are filled in
as each object is created and each robot starts, not at the end: when a step raises half-way,
the caller's teardown still removes exactly what was made, and the results still say how far
each robot got.
"""

from __future__ import annotations

import logging
import shutil
import time
from collections.abc import Callable, Mapping
from concurrent.futures import Future, ThreadPoolExecutor
from dataclasses import dataclass, field, replace
from pathlib import Path

from contracts import GC_RETURN_PORT, MAX_RENDER_PROCESSES, MatchSpec, Scalar, files
from orchestrator.bandwidth import AppliedShaping, RobotShaping, TrafficCounters, mb_s_to_bit
from orchestrator.errors import ImageError, InfrastructureError, OrchestratorError
from orchestrator.match import gate, layout
from orchestrator.match.admission import cpu_sets
from orchestrator.match.deps import MatchDeps
from orchestrator.match.events import RobotNotStarted
from orchestrator.match.layout import Subnet
from orchestrator.match.logfs import LogFolder
from orchestrator.match.placement import ROBOT_CGROUP_PARENT, LeaguePlacement, Node, firewall_for
from orchestrator.match.plan import MatchPlan, RobotPlan, per_robot_rate_mb_s
from orchestrator.match.results import Failure, FailureClass, RobotRecord
from orchestrator.runtime.port import (
    Attachment,
    BindMount,
    ContainerRequest,
    NetworkInfo,
    SubnetInUse,
)
from orchestrator.telemetry import TelemetrySource

log = logging.getLogger(__name__)

NODE_HOLDER_TIMEOUT_S = 20.0


@dataclass(slots=True)
class Created:
    """The ledger of everything a match created so far, so that teardown removes exactly that.

    :func:`start` enters each object as soon as the engine or the host has made it; collection
    (:func:`~orchestrator.match.collection.collect`) reads it to stop, collect and remove.
    """

    networks: dict[str, NetworkInfo] = field(default_factory=dict)  # role -> network
    subnets: dict[str, Subnet] = field(default_factory=dict)
    simulator_id: str | None = None
    holder_ids: dict[str, str] = field(default_factory=dict)  # robot key -> holder id
    robot_ids: dict[str, str] = field(default_factory=dict)  # robot key -> container id
    shaping: dict[str, AppliedShaping] = field(default_factory=dict)
    # robots behind the start gate: their network namespace ends with their container, so
    # their traffic counters are read while they run (the latest reading of each here)
    gated: set[str] = field(default_factory=set)
    counters: dict[str, TrafficCounters] = field(default_factory=dict)
    log_folders: dict[str, LogFolder] = field(default_factory=dict)
    scratch: dict[str, LogFolder] = field(default_factory=dict)  # robot key -> scratch space
    match_dir: Path | None = None  # the simulator's folder, once the match spec is in it
    # league placement: robot node firewalls made (node netns, None: this network) and the
    # shaping of robot nodes' interfaces (the nodes outlive the match: both are undone)
    node_firewalls: list[str | None] = field(default_factory=list)
    node_shaping: list[AppliedShaping] = field(default_factory=list)


@dataclass(frozen=True, slots=True, kw_only=True)
class StartupTimes:
    """The bring-up breakdown: seconds per step of STARTING (networks, firewall, spec,
    simulator, containers) and per robot and step of its start."""

    phases_s: Mapping[str, float]
    robot_steps_s: Mapping[str, Mapping[str, float]]


@dataclass(frozen=True, slots=True, kw_only=True)
class StartedMatch:
    """What STARTING hands on to the watch of the game."""

    simulator_id: str
    simulator_started_at: float  # the clock's time when the simulator's container ran
    robot_ids: Mapping[str, str]  # robot key -> container id of every robot created
    match_dir: Path  # the simulator's folder (match spec in, result files out)
    telemetry: TelemetrySource | None  # None: no telemetry planned or no factory given
    failure: Failure | None  # a team none of whose robots could be started (announced)
    times: StartupTimes


def start(deps: MatchDeps, created: Created, robots: Mapping[str, RobotRecord],
          started_at: float) -> StartedMatch:
    """Start everything. A robot that cannot start is recorded in its record (and published);
    a team without any fails the match. ``robots`` are the records of every planned robot
    (those with an ``image_error`` are not started); ``started_at`` is when STARTING began.

    Raises:
        OrchestratorError: a step the match cannot go on without failed; ``created`` holds
            what was made until then.
    """
    plan = deps.plan
    phases_s: dict[str, float] = {}
    mark = _Marks(deps.clock, phases_s)
    startable = [r for r in plan.robots if robots[r.key].entry.image_error is None]
    with ThreadPoolExecutor(max_workers=max(1, len(startable)),
                            thread_name_prefix="folders") as folders:
        # the robots' capped log and scratch folders are made from the start, while the
        # networks are made and the containers start
        made = {robot.key: folders.submit(_robot_folders, deps, created, robot)
                for robot in startable}
        return _start(deps, created, robots, started_at, made=made, phases_s=phases_s,
                      mark=mark)


def _start(deps: MatchDeps, created: Created, robots: Mapping[str, RobotRecord],
           started_at: float, *, made: Mapping[str, Future[tuple[LogFolder, LogFolder | None]]],
           phases_s: dict[str, float], mark: _Marks) -> StartedMatch:
    plan = deps.plan
    placement = deps.options.placement
    if placement is None:
        request, spec, endpoint = _dense_simulator(deps, created, mark)
    else:
        request, spec, endpoint = _league_simulator(deps, created, placement)
    # the cameras render in worker processes (on the CPU or a GPU), one per CPU the simulator
    # may use
    sets = cpu_sets(stepping=spec.stepping, robot_cpus=len(plan.robots) * plan.limits.cpus,
                    render_cpus=MAX_RENDER_PROCESSES)
    request = replace(request, cpuset_cpus=sets.simulator)
    mark("spec")
    robot_steps_s: dict[str, dict[str, float]] = {
        key: {} for key, record in robots.items() if record.entry.image_error is None}
    began, simulator_started_at = _start_containers(
        deps, created, robots, request, robot_cpuset=sets.robots, robot_steps_s=robot_steps_s,
        made=made)
    phases_s["simulator"] = round(simulator_started_at - began, 3)
    mark("containers")
    telemetry = None
    if endpoint is not None and deps.telemetry is not None:
        telemetry = deps.telemetry(endpoint, plan.match_id)
    failure = _team_failure(deps, robots)
    log.info("match %s: %d robot containers started in %.2f s", plan.match_id,
             len(created.robot_ids), deps.clock() - started_at)
    assert created.simulator_id is not None and created.match_dir is not None
    return StartedMatch(
        simulator_id=created.simulator_id, simulator_started_at=simulator_started_at,
        robot_ids=dict(created.robot_ids), match_dir=created.match_dir, telemetry=telemetry,
        failure=failure,
        times=StartupTimes(phases_s=phases_s, robot_steps_s=robot_steps_s),
    )


def _team_failure(deps: MatchDeps, robots: Mapping[str, RobotRecord]) -> Failure | None:
    failure = None
    for team in deps.plan.teams:
        tried = [r for r in team.robots if robots[r.key].entry.image_error is None]
        failed = [r for r in tried if robots[r.key].entry.startup_error is not None]
        if tried and len(failed) == len(tried):
            failure = deps.fail(failure, FailureClass.TEAM_STARTUP,
                                f"no robot of {team.color} could be started: "
                                f"{robots[failed[0].key].entry.startup_error}")
    return failure


def _create_network(deps: MatchDeps, created: Created, role: str, internal: bool) -> None:
    plan = deps.plan
    taken = {str(s.network) for s in created.subnets.values()}
    for subnet in layout.candidate_subnets(f"{plan.match_id}/{role}"):
        if str(subnet.network) in taken:
            continue
        request = layout.network_request(
            prefix=deps.prefix, role=role, subnet=subnet, internal=internal,
            match_id=plan.match_id, extra_labels=deps.options.extra_labels,
        )
        try:
            created.networks[role] = deps.runtime.create_network(request)
        except SubnetInUse:
            continue
        created.subnets[role] = subnet
        return
    raise InfrastructureError(f"no free /24 in 10.213.0.0/16 for the {role} network")


def _dense_simulator(deps: MatchDeps, created: Created, mark: _Marks
                     ) -> tuple[ContainerRequest, MatchSpec, str | None]:
    """Dense placement: a network per team and one for control (the simulator on all three),
    the teams' bridges isolated; returns the simulator's request, the spec and the telemetry
    endpoint."""
    plan = deps.plan
    roles = (("control", True), ("red", not plan.allow_internet),
             ("blue", not plan.allow_internet))
    with ThreadPoolExecutor(max_workers=len(roles)) as pool:  # side by side (a subnet taken
        # meanwhile by another is SubnetInUse: the next candidate is tried)
        list(pool.map(lambda role: _create_network(deps, created, *role), roles))
    mark("networks")
    for color in ("red", "blue"):
        deps.host.isolate_bridge(created.networks[color].bridge_name, match_id=plan.match_id)
    mark("firewall")

    addresses = {
        team.color: tuple(created.subnets[team.color].robot(r.number) for r in team.robots)
        for team in plan.teams
    }
    control = created.subnets["control"]
    endpoint = f"tcp/{control.simulator}:{layout.TELEMETRY_PORT}" if plan.telemetry else None
    spec, match_dir = _write_spec(deps, created, addresses, endpoint)
    attachments = tuple(
        Attachment(
            network=created.networks[role].name,
            ipv4_address=created.subnets[role].simulator,
            aliases=("simulator",),
        )
        for role in ("control", "red", "blue")
    )
    request = layout.simulator_request(
        plan, prefix=deps.prefix, image=deps.options.simulator_image, match_dir=match_dir,
        attachments=attachments, extra_labels=deps.options.extra_labels,
        command=deps.options.simulator_command, model_dirs=plan.model_dirs,
        gpu=deps.options.gpu,
    )
    return request, spec, endpoint


def _write_spec(deps: MatchDeps, created: Created, addresses: dict[str, tuple[str, ...]],
                endpoint: str | None) -> tuple[MatchSpec, Path]:
    match_dir = deps.options.out_dir / "simulator"
    (match_dir / files.OUT_DIR).mkdir(parents=True, exist_ok=True)
    for folder in (match_dir, match_dir / files.OUT_DIR):
        folder.chmod(0o777)
    created.match_dir = match_dir
    spec = deps.plan.spec_builder(addresses, endpoint)
    spec.write(match_dir / files.MATCH_SPEC)
    return spec, match_dir


def _league_simulator(deps: MatchDeps, created: Created, placement: LeaguePlacement
                      ) -> tuple[ContainerRequest, MatchSpec, str | None]:
    """League placement: no Docker networks; the simulator has its node's network and address,
    each robot its own node's (see :mod:`orchestrator.match.placement`)."""
    plan = deps.plan
    addresses = {
        team.color: tuple(placement.robots[r.key].address for r in team.robots)
        for team in plan.teams
    }
    simulator_ip = placement.simulator.address
    endpoint = f"tcp/{simulator_ip}:{layout.TELEMETRY_PORT}" if plan.telemetry else None
    spec, match_dir = _write_spec(deps, created, addresses, endpoint)
    holder = _node_holder(deps, created, placement, placement.simulator, key="simulator")
    request = layout.simulator_request(
        plan, prefix=deps.prefix, image=deps.options.simulator_image,
        match_dir=match_dir, attachments=(), extra_labels=deps.options.extra_labels,
        command=deps.options.simulator_command, model_dirs=plan.model_dirs,
        gpu=deps.options.gpu,
    )
    request = replace(request, network_mode=f"container:{holder}", hostname=None,
                      labels={**request.labels, layout.LABEL_NODE: placement.simulator.name})
    return request, spec, endpoint


def _node_holder(deps: MatchDeps, created: Created, placement: LeaguePlacement, node: Node, *,
                 key: str) -> str:
    """The holder container that gives ``key``'s containers the network of ``node``."""
    netns = placement.netns_of(node)
    if netns is None:
        raise InfrastructureError(
            f"league placement of {key} on node {node.name}: no network namespace of the node "
            "(this orchestrator starts containers on nodes that share its Docker engine)")
    request = layout.node_holder_request(
        node.name, prefix=deps.prefix,
        image=deps.options.holder_image or deps.options.simulator_image, netns=netns,
        match_id=deps.plan.match_id, extra_labels=deps.options.extra_labels,
    )
    runtime = deps.runtime
    holder_id = runtime.create_container(request)
    created.holder_ids[key] = holder_id
    runtime.start(holder_id)
    # a container started in the holder's network joins the namespace the holder's process
    # is in at that moment: wait until nsenter has entered the node's
    deadline = deps.clock() + NODE_HOLDER_TIMEOUT_S
    while not deps.host.in_netns(runtime.inspect(holder_id).pid, netns):
        if deps.clock() > deadline or runtime.inspect(holder_id).exited:
            raise InfrastructureError(
                f"league placement of {key}: the holder of node {node.name} did not enter "
                f"{netns} within {NODE_HOLDER_TIMEOUT_S:.0f} s")
        time.sleep(0.02)
    return holder_id


def _start_containers(
    deps: MatchDeps, created: Created, robots: Mapping[str, RobotRecord],
    request: ContainerRequest, *, robot_cpuset: str | None,
    robot_steps_s: dict[str, dict[str, float]],
    made: Mapping[str, Future[tuple[LogFolder, LogFolder | None]]],
) -> tuple[float, float]:
    """The simulator and every robot with an image; returns when the simulator's start began
    and when it was done."""
    plan = deps.plan
    startable = [r for r in plan.robots if robots[r.key].entry.image_error is None]
    team_size = {team.color: len([r for r in team.robots
                                  if robots[r.key].entry.image_error is None])
                 for team in plan.teams}
    # the simulator and the robots start at the same time (robot clients retry until the
    # simulator listens); the simulator is submitted first so that it boots while they start
    with ThreadPoolExecutor(max_workers=len(startable) + 1) as pool:
        simulator = pool.submit(_start_simulator, deps, created, request)
        list(pool.map(lambda robot: _start_robot(
            deps, created, robot, robots[robot.key], n_robots=team_size[robot.color],
            cpuset=robot_cpuset, mark=_Marks(deps.clock, robot_steps_s[robot.key]),
            made=made[robot.key]), startable))
        return simulator.result()


def _start_simulator(deps: MatchDeps, created: Created, request: ContainerRequest
                     ) -> tuple[float, float]:
    """Started with the robots, so that it boots while they start (robot clients retry). Under
    ``gpu`` "auto", an engine that refuses the GPU (a driver or toolkit problem that detection
    could not see) gets the simulator without it: cameras on the CPU, said in the log. Returns
    when its start began and when it was done."""
    runtime = deps.runtime
    began = deps.clock()
    gpu = deps.options.gpu
    try:
        created.simulator_id = runtime.create_container(request)
        runtime.start(created.simulator_id)
    except InfrastructureError as exc:
        if gpu is None or gpu.mode != "auto":
            raise
        log.warning("match %s: the engine refused the simulator the GPU (%s); gpu auto: it "
                    "renders its cameras on the CPU", deps.plan.match_id, exc)
        if created.simulator_id is not None:
            runtime.remove(created.simulator_id)
            created.simulator_id = None
        request = gpu.taken_from(request)
        created.simulator_id = runtime.create_container(request)
        runtime.start(created.simulator_id)
    started_at = deps.clock()
    log.info("match %s: simulator container %s started (%s)", deps.plan.match_id,
             request.name, request.image)
    deps.monitor.watch("simulator", created.simulator_id)
    return began, started_at


def _start_robot(
    deps: MatchDeps, created: Created, robot: RobotPlan, record: RobotRecord, *,
    n_robots: int, cpuset: str | None, mark: _Marks,
    made: Future[tuple[LogFolder, LogFolder | None]],
) -> None:
    """Start one robot (``n_robots``: how many of its team start, who share its team's
    bandwidth); what goes wrong is its ``startup_error``, never an exception. With the start
    gate (:mod:`orchestrator.match.gate`; dense placement) the robot container is started
    behind it, shaped and then released; else a holder is started and shaped first and the
    robot container joins its network."""
    plan = deps.plan
    placement = deps.options.placement
    team = plan.red if robot.color == "red" else plan.blue
    limits = plan.limits
    binary = deps.options.start_gate if placement is None else None
    try:
        holder_id, team_net, applied, cgroup_parent = _robot_network(
            deps, created, robot, n_robots, mark, gated=binary is not None)
        if applied is not None:
            created.shaping[robot.key] = applied
        if binary is None:  # shaped in its holder (behind the gate: once started)
            mark("shaping")
        folder, scratch = made.result()
        mark("folders")
        environment = layout.robot_environment(
            robot, team_net=team_net, player_count=len(team.robots),
            gamecontroller_ip=team_net.simulator,
        )
        image = record.entry.digest or robot.image
        request = layout.robot_request(
            replace(robot, image=image),
            prefix=deps.prefix, holder_id=holder_id, environment=environment,
            logs_dir=folder.path, limits=limits, match_id=plan.match_id,
            extra_labels=deps.options.extra_labels,
            scratch_dir=scratch.path if scratch is not None else None,
            cgroup_parent=cgroup_parent,
        )
        request = replace(request, cpuset_cpus=cpuset)
        gate_dir = None
        if binary is not None:
            assert image is not None
            gate_dir = gate.folder(deps.options.out_dir, robot.key)
            request = _gated_request(deps, robot, request, binary=binary, gate_dir=gate_dir,
                                     image=image, team_net=team_net,
                                     network=created.networks[robot.color].name)
        if placement is not None:  # the node's epilog finds it by this label
            node = placement.robots[robot.key].name
            request = replace(request, labels={**request.labels, layout.LABEL_NODE: node})
        record.entry = replace(record.entry, limits=_robot_limits(
            plan, folder, scratch, applied, request.cpuset_cpus))
        container_id = deps.runtime.create_container(request)
        created.robot_ids[robot.key] = container_id
        record.entry = replace(record.entry, container=request.name)
        mark("create")
        deps.runtime.start(container_id)
        mark("start")
        if gate_dir is not None:
            applied = _shape_gated(deps, robot, container_id, n_robots, team_net)
            if applied is not None:
                created.shaping[robot.key] = applied
                created.gated.add(robot.key)
            record.entry = replace(record.entry, limits=_robot_limits(
                plan, folder, scratch, applied, request.cpuset_cpus))
            mark("shaping")
            gate.release(gate_dir)
            mark("release")
        deps.monitor.watch(robot.key, container_id)
        log.info("match %s: robot %s started (%s, %s)", plan.match_id, robot.key, robot.image,
                 team_net.robot(robot.number))
    except OrchestratorError as exc:
        record.entry = replace(record.entry, startup_error=str(exc))
        deps.events.publish(RobotNotStarted(key=robot.key, color=record.color,
                                            image=record.entry.image, cause=str(exc)))
        log.warning("match %s: robot %s could not be started: %s", plan.match_id, robot.key, exc)
    finally:
        made.exception()  # made and recorded (for the teardown) even when the robot failed


def _robot_network(deps: MatchDeps, created: Created, robot: RobotPlan, n_robots: int,
                   mark: _Marks, *, gated: bool,
                   ) -> tuple[str | None, layout.TeamAddresses, AppliedShaping | None, str | None]:
    """The robot's holder (None: ``gated``, the robot has its team's network itself), its
    team's addresses, the limits applied to the holder and the robot's cgroup parent."""
    placement = deps.options.placement
    if placement is not None:
        return _league_robot_network(deps, created, robot, placement, n_robots, mark)
    if gated:
        return None, created.subnets[robot.color], None, None
    holder_id, team_net, applied = _dense_robot_network(deps, created, robot, n_robots, mark)
    return holder_id, team_net, applied, None


def _robot_limits(plan: MatchPlan, folder: LogFolder, scratch: LogFolder | None,
                  applied: AppliedShaping | None, cpuset: str | None) -> dict[str, Scalar]:
    """The limits a robot runs under, as ``report.json`` records them."""
    limits = plan.limits
    return {
        "nano_cpus": int(limits.cpus * 1e9),
        "memory_bytes": int(limits.memory_gb * 1e9),
        "pids": limits.pids,
        "log_folder_bytes": folder.cap_bytes,
        "scratch_bytes": scratch.cap_bytes if scratch is not None else None,
        "read_only_root": True,
        # the OCI runtime the robot ran under ("runsc": gVisor), None: the engine's default
        "runtime": limits.robot_runtime or None,
        "console_bytes": layout.ROBOT_CONSOLE_BYTES,  # what the engine keeps of its output
        "api_rate_bit_s": applied.api_rate_bit if applied else None,
        "comm_rate_bit_s": applied.comm_rate_bit if applied else None,
        "shaping_applied_ms": round(applied.applied_ms, 1) if applied else None,
        "cpuset": cpuset,
    }


def _gated_request(deps: MatchDeps, robot: RobotPlan, request: ContainerRequest, *,
                   binary: Path, gate_dir: Path, image: str, team_net: layout.TeamAddresses,
                   network: str) -> ContainerRequest:
    """``request`` behind the start gate: on its team's network with its fixed address and
    name (what its holder had), the gate as its entry point, then the image's entry point and
    the team's command (or the image's)."""
    prefix = (gate.TARGET, gate.DIR_TARGET, "--")
    entrypoint, command = gate.gated_launch(prefix, robot.command,
                                            deps.runtime.image_launch(image))
    if entrypoint == prefix and not command:
        raise ImageError(image=robot.image or image, reason=(
            f"robot {robot.key}: the image has no entry point or command and the team "
            "configuration gives no dockerCmd: nothing to run"))
    return replace(
        request,
        entrypoint=entrypoint,
        command=command,
        network_mode=None,
        networks=(Attachment(network=network,
                             ipv4_address=team_net.robot(robot.number),
                             aliases=(robot.key,)),),
        hostname=robot.key,
        mounts=(*request.mounts,
                BindMount(source=binary, target=gate.TARGET, read_only=True),
                BindMount(source=gate_dir, target=gate.DIR_TARGET, read_only=True)),
    )


def _shape_gated(deps: MatchDeps, robot: RobotPlan, container_id: str, n_robots: int,
                 team_net: layout.TeamAddresses) -> AppliedShaping | None:
    """The bandwidth limits of a robot waiting behind its gate; a robot that cannot be shaped
    is killed there, before anything of it ran."""
    shaping = _dense_shaping(deps.plan, robot, n_robots, team_net)
    try:
        return deps.host.shape(deps.runtime.inspect(container_id).pid, shaping)
    except OrchestratorError:
        try:
            deps.runtime.kill(container_id)
        except OrchestratorError as exc:
            log.warning("match %s: robot %s could not be shaped nor killed behind its start "
                        "gate: %s", deps.plan.match_id, robot.key, exc)
        raise


def _robot_folders(deps: MatchDeps, created: Created, robot: RobotPlan
                   ) -> tuple[LogFolder, LogFolder | None]:
    """The robot's capped /robocup-logs folder and its scratch space."""
    folder = deps.host.log_folder(
        match_id=deps.plan.match_id, name=robot.key,
        cap_bytes=int(deps.plan.limits.log_folder_gb * 1e9),
        fallback=deps.options.out_dir / "teams" / robot.color / str(robot.number)
        / "robocup-logs",
    )
    created.log_folders[robot.key] = folder
    return folder, _scratch(deps, created, robot)


def _shaping(plan: MatchPlan, n_robots: int, *, simulator_ip: str,
             teammate_ips: tuple[str, ...]) -> RobotShaping:
    limits = plan.limits
    return RobotShaping(
        api_rate_bit=mb_s_to_bit(per_robot_rate_mb_s(limits.team_api_mb_s, n_robots)),
        comm_rate_bit=mb_s_to_bit(per_robot_rate_mb_s(limits.team_comm_mb_s, n_robots)),
        simulator_ip=simulator_ip, teammate_ips=teammate_ips, mirror_port=plan.mirror_port,
    )


def _dense_robot_network(deps: MatchDeps, created: Created, robot: RobotPlan, n_robots: int,
                         mark: _Marks
                         ) -> tuple[str, layout.TeamAddresses, AppliedShaping | None]:
    """A holder on the team's network with the robot's fixed address, shaped."""
    plan = deps.plan
    subnet = created.subnets[robot.color]
    holder = layout.holder_request(
        robot, prefix=deps.prefix,
        image=deps.options.holder_image or deps.options.simulator_image,
        network=created.networks[robot.color].name, team_net=subnet, match_id=plan.match_id,
        extra_labels=deps.options.extra_labels,
    )
    holder_id = deps.runtime.create_container(holder)
    created.holder_ids[robot.key] = holder_id
    deps.runtime.start(holder_id)
    pid = deps.runtime.inspect(holder_id).pid
    mark("holder")
    return holder_id, subnet, deps.host.shape(pid, _dense_shaping(plan, robot, n_robots, subnet))


def _dense_shaping(plan: MatchPlan, robot: RobotPlan, n_robots: int,
                   team_net: layout.TeamAddresses) -> RobotShaping:
    """The limits of a robot on its team's network (its teammates at their fixed addresses)."""
    team = plan.red if robot.color == "red" else plan.blue
    return _shaping(plan, n_robots, simulator_ip=team_net.simulator, teammate_ips=tuple(
        team_net.robot(r.number) for r in team.robots if r != robot))


def _league_robot_network(
    deps: MatchDeps, created: Created, robot: RobotPlan, placement: LeaguePlacement,
    n_robots: int, mark: _Marks,
) -> tuple[str, layout.TeamAddresses, AppliedShaping | None, str | None]:
    """The robot's node: its firewall (before anything of the robot runs), a holder in the
    node's network, the limits on the node's interface."""
    plan = deps.plan
    team = plan.red if robot.color == "red" else plan.blue
    node = placement.robots[robot.key]
    netns = placement.netns_of(node)
    firewall = firewall_for(placement, color=robot.color, number=robot.number,
                            api_port=robot.port, udp_ports=(plan.mirror_port, GC_RETURN_PORT))
    cgroup_parent = None
    if deps.host.node_firewall(netns, firewall):
        created.node_firewalls.append(netns)
        cgroup_parent = ROBOT_CGROUP_PARENT
    mark("firewall")
    holder_id = _node_holder(deps, created, placement, node, key=robot.key)
    mark("holder")
    applied = None
    if netns is not None:
        applied = deps.host.shape_node(netns, _shaping(
            plan, n_robots, simulator_ip=placement.simulator.address,
            teammate_ips=firewall.teammates))
        if applied is not None:
            created.node_shaping.append(applied)
    team_net = placement.addresses(robot.color, [r.number for r in team.robots])
    return holder_id, team_net, applied, cgroup_parent


class _Marks:
    """Records the seconds since the previous mark under each name (bring-up breakdown)."""

    def __init__(self, clock: Callable[[], float], into: dict[str, float]) -> None:
        self._clock = clock
        self._into = into
        self._last = clock()

    def __call__(self, name: str) -> None:
        now = self._clock()
        self._into[name] = round(now - self._last, 3)
        self._last = now


def _scratch(deps: MatchDeps, created: Created, robot: RobotPlan) -> LogFolder | None:
    """The robot's capped scratch space with its :data:`layout.SCRATCH_DIRS`, or None when no
    cap can be applied (the robot then gets small tmpfs folders)."""
    cap = int(deps.plan.limits.scratch_gb * 1e9)
    out_dir = deps.options.out_dir
    scratch = deps.host.log_folder(
        match_id=deps.plan.match_id, name=f"{robot.key}-scratch", cap_bytes=cap,
        fallback=out_dir / ".scratch" / robot.key,
    )
    if scratch.cap_bytes is None:
        shutil.rmtree(out_dir / ".scratch", ignore_errors=True)
        return None
    created.scratch[robot.key] = scratch
    for name in layout.SCRATCH_DIRS:
        path = scratch.path / name
        path.mkdir(exist_ok=True)
        path.chmod(0o700 if name == "root" else 0o1777)
    return scratch


def read_gated_counters(deps: MatchDeps, created: Created, key: str) -> None:
    """Read the traffic counters of gated robot ``key`` while its namespace lives (kept in
    ``created.counters``; a failed reading keeps the previous one and is logged at debug
    level: the robot may just have ended)."""
    applied = created.shaping.get(key)
    if applied is None or key not in created.gated:
        return
    try:
        created.counters[key] = deps.host.counters(applied)
    except OrchestratorError as exc:
        log.debug("match %s: traffic counters of %s not read: %s", deps.plan.match_id, key, exc)


__all__ = ["Created", "StartedMatch", "StartupTimes", "read_gated_counters", "start"]
