"""STARTING: networks, host firewall, match spec, simulator, then the robots in parallel.

:class:`StartupPhase` runs it on a :class:`~orchestrator.match.context.MatchContext`.
"""

from __future__ import annotations

import logging
import shutil
import time
from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor
from dataclasses import replace
from pathlib import Path

from contracts import GC_RETURN_PORT, MatchSpec, files
from orchestrator.bandwidth import AppliedShaping, RobotShaping, mb_s_to_bit
from orchestrator.errors import InfrastructureError, OrchestratorError
from orchestrator.match import layout
from orchestrator.match.admission import cpu_sets
from orchestrator.match.context import MatchContext, Started
from orchestrator.match.events import RobotNotStarted
from orchestrator.match.logfs import LogFolder, safe_name
from orchestrator.match.placement import (
    ROBOT_CGROUP_PARENT,
    LeaguePlacement,
    Node,
    firewall_for,
)
from orchestrator.match.plan import RobotPlan, per_robot_rate_mb_s
from orchestrator.match.results import FailureClass
from orchestrator.match.runtime import Attachment, ContainerRequest, SubnetInUse

log = logging.getLogger(__name__)

NODE_HOLDER_TIMEOUT_S = 20.0


def _create_network(match: MatchContext, role: str, internal: bool) -> None:
    plan = match.plan
    started = match.started
    taken = {str(s.network) for s in started.subnets.values()}
    for subnet in layout.candidate_subnets(f"{plan.match_id}/{role}"):
        if str(subnet.network) in taken:
            continue
        request = layout.network_request(
            prefix=started.prefix, role=role, subnet=subnet, internal=internal,
            match_id=plan.match_id, extra_labels=match.options.extra_labels,
        )
        try:
            started.networks[role] = match.runtime.create_network(request)
        except SubnetInUse:
            continue
        started.subnets[role] = subnet
        return
    raise InfrastructureError(f"no free /24 in 10.213.0.0/16 for the {role} network")


def _start(match: MatchContext, started_at: float) -> None:
    plan = match.plan
    started = match.started
    started.prefix = f"hlvs-{safe_name(plan.match_id)}"
    mark = _Marks(match.clock, started.phases_s)
    placement = match.options.placement
    if placement is not None:
        _start_league(match, started_at, placement, mark)
        return
    roles = (("control", True), ("red", not plan.allow_internet),
             ("blue", not plan.allow_internet))
    with ThreadPoolExecutor(max_workers=len(roles)) as pool:  # side by side (a subnet taken
        # meanwhile by another is SubnetInUse: the next candidate is tried)
        list(pool.map(lambda role: _create_network(match, *role), roles))
    mark("networks")
    for color in ("red", "blue"):
        match.host.isolate_bridge(started.networks[color].bridge_name, match_id=plan.match_id)
    mark("firewall")

    addresses = {
        team.color: tuple(started.subnets[team.color].robot(r.number) for r in team.robots)
        for team in plan.teams
    }
    control = started.subnets["control"]
    endpoint = f"tcp/{control.simulator}:{layout.TELEMETRY_PORT}" if plan.telemetry else None
    spec, match_dir = _write_spec(match, addresses, endpoint)

    attachments = tuple(
        Attachment(
            network=started.networks[role].name,
            ipv4_address=started.subnets[role].simulator,
            aliases=("simulator",),
        )
        for role in ("control", "red", "blue")
    )
    request = layout.simulator_request(
        plan, prefix=started.prefix, image=match.options.simulator_image, match_dir=match_dir,
        attachments=attachments, extra_labels=match.options.extra_labels,
        command=match.options.simulator_command, model_dirs=plan.model_dirs,
        gpu=match.options.gpu,
    )
    sets = cpu_sets(stepping=spec.stepping)
    started.cpu_sets = sets
    request = replace(request, cpuset_cpus=sets.simulator)
    mark("spec")
    _start_containers(match, request, started_at, endpoint, mark)


def _write_spec(match: MatchContext, addresses: dict[str, tuple[str, ...]],
                endpoint: str | None) -> tuple[MatchSpec, Path]:
    match_dir = match.options.out_dir / "simulator"
    (match_dir / files.OUT_DIR).mkdir(parents=True, exist_ok=True)
    for folder in (match_dir, match_dir / files.OUT_DIR):
        folder.chmod(0o777)
    match.started.match_dir = match_dir
    spec = match.plan.spec_builder(addresses, endpoint)
    spec.write(match_dir / files.MATCH_SPEC)
    return spec, match_dir


def _start_league(match: MatchContext, started_at: float, placement: LeaguePlacement,
                  mark: _Marks) -> None:
    """League placement: no Docker networks; the simulator has its node's network and address,
    each robot its own node's (see :mod:`orchestrator.match.placement`)."""
    plan = match.plan
    addresses = {
        team.color: tuple(placement.robots[r.key].address for r in team.robots)
        for team in plan.teams
    }
    simulator_ip = placement.simulator.address
    endpoint = f"tcp/{simulator_ip}:{layout.TELEMETRY_PORT}" if plan.telemetry else None
    spec, match_dir = _write_spec(match, addresses, endpoint)
    holder = _node_holder(match, placement, placement.simulator, key="simulator")
    request = layout.simulator_request(
        plan, prefix=match.started.prefix, image=match.options.simulator_image,
        match_dir=match_dir, attachments=(), extra_labels=match.options.extra_labels,
        command=match.options.simulator_command, model_dirs=plan.model_dirs,
        gpu=match.options.gpu,
    )
    request = replace(request, network_mode=f"container:{holder}", hostname=None,
                      labels={**request.labels, layout.LABEL_NODE: placement.simulator.name})
    sets = cpu_sets(stepping=spec.stepping)
    match.started.cpu_sets = sets
    request = replace(request, cpuset_cpus=sets.simulator)
    mark("spec")
    _start_containers(match, request, started_at, endpoint, mark)


def _node_holder(match: MatchContext, placement: LeaguePlacement, node: Node, *, key: str
                 ) -> str:
    """The holder container that gives ``key``'s containers the network of ``node``."""
    netns = placement.netns_of(node)
    if netns is None:
        raise InfrastructureError(
            f"league placement of {key} on node {node.name}: no network namespace of the node "
            "(this orchestrator starts containers on nodes that share its Docker engine)")
    request = layout.node_holder_request(
        node.name, prefix=match.started.prefix,
        image=match.options.holder_image or match.options.simulator_image, netns=netns,
        match_id=match.plan.match_id, extra_labels=match.options.extra_labels,
    )
    holder_id = match.runtime.create_container(request)
    match.started.holder_ids[key] = holder_id
    match.runtime.start(holder_id)
    # a container started in the holder's network joins the namespace the holder's process
    # is in at that moment: wait until nsenter has entered the node's
    deadline = match.clock() + NODE_HOLDER_TIMEOUT_S
    while not match.host.in_netns(match.runtime.inspect(holder_id).pid, netns):
        if match.clock() > deadline or match.runtime.inspect(holder_id).exited:
            raise InfrastructureError(
                f"league placement of {key}: the holder of node {node.name} did not enter "
                f"{netns} within {NODE_HOLDER_TIMEOUT_S:.0f} s")
        time.sleep(0.02)
    return holder_id


def _start_containers(match: MatchContext, request: ContainerRequest, started_at: float,
                      endpoint: str | None, mark: _Marks) -> None:
    plan = match.plan
    started = match.started
    robots = [r for r in plan.robots if match.records[r.key].image_error is None]
    # the simulator and the robots start at the same time (robot clients retry until the
    # simulator listens); the simulator is submitted first so that it boots while they start
    with (ThreadPoolExecutor(max_workers=len(robots) + 1) as pool,
          ThreadPoolExecutor(max_workers=max(1, len(robots)), thread_name_prefix="folders")
          as folders):
        simulator = pool.submit(_start_simulator, match, request)
        list(pool.map(lambda robot: _start_robot(match, robot, folders), robots))
        simulator.result()
    mark("containers")
    if endpoint is not None and match.telemetry_factory is not None:
        match.telemetry = match.telemetry_factory(endpoint, plan.match_id)
    for team in plan.teams:
        tried = [r for r in team.robots if match.records[r.key].image_error is None]
        failed = [r for r in tried if match.records[r.key].startup_error is not None]
        if tried and len(failed) == len(tried):
            match.fail(FailureClass.TEAM_STARTUP, f"no robot of {team.color} could be started: "
                         f"{match.records[failed[0].key].startup_error}")
    log.info("match %s: %d robot containers started in %.2f s", plan.match_id,
             len(started.robot_ids), match.clock() - started_at)


def _start_simulator(match: MatchContext, request: ContainerRequest) -> None:
    """Started with the robots, so that it boots while they start (robot clients retry). Under
    ``gpu`` "auto", an engine that refuses the GPU (a driver or toolkit problem that detection
    could not see) gets the simulator without it: cameras on the CPU, said in the log."""
    started = match.started
    began = match.clock()
    gpu = match.options.gpu
    try:
        started.simulator_id = match.runtime.create_container(request)
        match.runtime.start(started.simulator_id)
    except InfrastructureError as exc:
        if gpu is None or gpu.mode != "auto":
            raise
        log.warning("match %s: the engine refused the simulator the GPU (%s); gpu auto: it "
                    "renders its cameras on the CPU", match.plan.match_id, exc)
        if started.simulator_id is not None:
            match.runtime.remove(started.simulator_id)
            started.simulator_id = None
        request = gpu.taken_from(request)
        started.simulator_id = match.runtime.create_container(request)
        match.runtime.start(started.simulator_id)
    started.simulator_started_at = match.clock()
    started.phases_s["simulator"] = round(started.simulator_started_at - began, 3)
    log.info("match %s: simulator container %s started (%s)", match.plan.match_id,
             request.name, request.image)
    match.monitor.watch("simulator", started.simulator_id)


def _start_robot(match: MatchContext, robot: RobotPlan, folders: ThreadPoolExecutor) -> None:
    plan = match.plan
    started = match.started
    record = match.records[robot.key]
    team = plan.red if robot.color == "red" else plan.blue
    n_robots = len([r for r in team.robots if match.records[r.key].image_error is None])
    limits = plan.limits
    mark = _Marks(match.clock, started.robot_steps_s.setdefault(robot.key, {}))
    # the capped log and scratch folders are made while the holder starts
    made = folders.submit(_robot_folders, match, robot)
    try:
        if match.options.placement is not None:
            holder_id, team_net, applied, cgroup_parent = _league_robot_network(
                match, robot, match.options.placement, n_robots, mark)
        else:
            holder_id, team_net, applied = _dense_robot_network(match, robot, n_robots, mark)
            cgroup_parent = None
        if applied is not None:
            started.shaping[robot.key] = applied
        mark("shaping")
        folder, scratch = made.result()
        mark("folders")
        record.limits = {
            "nano_cpus": int(limits.cpus * 1e9),
            "memory_bytes": int(limits.memory_gb * 1e9),
            "pids": limits.pids,
            "log_folder_bytes": folder.cap_bytes,
            "scratch_bytes": scratch.cap_bytes if scratch is not None else None,
            "read_only_root": True,
            "console_bytes": layout.ROBOT_CONSOLE_BYTES,  # what the engine keeps of its output
            "api_rate_bit_s": applied.api_rate_bit if applied else None,
            "comm_rate_bit_s": applied.comm_rate_bit if applied else None,
            "shaping_applied_ms": round(applied.applied_ms, 1) if applied else None,
        }
        environment = layout.robot_environment(
            robot, team_net=team_net, player_count=len(team.robots),
            gamecontroller_ip=team_net.simulator,
        )
        request = layout.robot_request(
            replace(robot, image=record.digest or robot.image),
            prefix=started.prefix, holder_id=holder_id, environment=environment,
            logs_dir=folder.path, limits=limits, match_id=plan.match_id,
            extra_labels=match.options.extra_labels,
            scratch_dir=scratch.path if scratch is not None else None,
            cgroup_parent=cgroup_parent,
        )
        request = replace(request, cpuset_cpus=started.cpu_sets.robots)
        if match.options.placement is not None:  # the node's epilog finds it by this label
            node = match.options.placement.robots[robot.key].name
            request = replace(request, labels={**request.labels, layout.LABEL_NODE: node})
        record.limits["cpuset"] = request.cpuset_cpus
        container_id = match.runtime.create_container(request)
        started.robot_ids[robot.key] = container_id
        record.container = request.name
        mark("create")
        match.runtime.start(container_id)
        mark("start")
        match.monitor.watch(robot.key, container_id)
        log.info("match %s: robot %s started (%s, %s)", plan.match_id, robot.key, robot.image,
                 team_net.robot(robot.number))
    except OrchestratorError as exc:
        record.startup_error = str(exc)
        match.events.publish(RobotNotStarted(key=robot.key, color=record.color,
                                             image=record.image, cause=str(exc)))
        log.warning("match %s: robot %s could not be started: %s", plan.match_id, robot.key, exc)
    finally:
        made.exception()  # made and recorded (for the teardown) even when the robot failed


def _robot_folders(match: MatchContext, robot: RobotPlan) -> tuple[LogFolder, LogFolder | None]:
    """The robot's capped /robocup-logs folder and its scratch space."""
    folder = match.host.log_folder(
        match_id=match.plan.match_id, name=robot.key,
        cap_bytes=int(match.plan.limits.log_folder_gb * 1e9),
        fallback=match.options.out_dir / "teams" / robot.color / str(robot.number)
        / "robocup-logs",
    )
    match.started.log_folders[robot.key] = folder
    return folder, _scratch(match, robot)


def _shaping(match: MatchContext, n_robots: int, *, simulator_ip: str,
             teammate_ips: tuple[str, ...]) -> RobotShaping:
    limits = match.plan.limits
    return RobotShaping(
        api_rate_bit=mb_s_to_bit(per_robot_rate_mb_s(limits.team_api_mb_s, n_robots)),
        comm_rate_bit=mb_s_to_bit(per_robot_rate_mb_s(limits.team_comm_mb_s, n_robots)),
        simulator_ip=simulator_ip, teammate_ips=teammate_ips, mirror_port=match.plan.mirror_port,
    )


def _dense_robot_network(match: MatchContext, robot: RobotPlan, n_robots: int, mark: _Marks
                         ) -> tuple[str, layout.TeamAddresses, AppliedShaping | None]:
    """A holder on the team's network with the robot's fixed address, shaped."""
    plan = match.plan
    started = match.started
    team = plan.red if robot.color == "red" else plan.blue
    subnet = started.subnets[robot.color]
    holder = layout.holder_request(
        robot, prefix=started.prefix,
        image=match.options.holder_image or match.options.simulator_image,
        network=started.networks[robot.color].name, team_net=subnet, match_id=plan.match_id,
        extra_labels=match.options.extra_labels,
    )
    holder_id = match.runtime.create_container(holder)
    started.holder_ids[robot.key] = holder_id
    match.runtime.start(holder_id)
    pid = match.runtime.inspect(holder_id).pid
    mark("holder")
    shaping = _shaping(match, n_robots, simulator_ip=subnet.simulator, teammate_ips=tuple(
        subnet.robot(r.number) for r in team.robots if r != robot))
    return holder_id, subnet, match.host.shape(pid, shaping)


def _league_robot_network(
    match: MatchContext, robot: RobotPlan, placement: LeaguePlacement, n_robots: int,
    mark: _Marks,
) -> tuple[str, layout.TeamAddresses, AppliedShaping | None, str | None]:
    """The robot's node: its firewall (before anything of the robot runs), a holder in the
    node's network, the limits on the node's interface."""
    plan = match.plan
    started = match.started
    team = plan.red if robot.color == "red" else plan.blue
    node = placement.robots[robot.key]
    netns = placement.netns_of(node)
    firewall = firewall_for(placement, color=robot.color, number=robot.number,
                            api_port=robot.port, udp_ports=(plan.mirror_port, GC_RETURN_PORT))
    cgroup_parent = None
    if match.host.node_firewall(netns, firewall):
        started.node_firewalls.append(netns)
        cgroup_parent = ROBOT_CGROUP_PARENT
    mark("firewall")
    holder_id = _node_holder(match, placement, node, key=robot.key)
    mark("holder")
    applied = None
    if netns is not None:
        applied = match.host.shape_node(netns, _shaping(
            match, n_robots, simulator_ip=placement.simulator.address,
            teammate_ips=firewall.teammates))
        if applied is not None:
            started.node_shaping.append(applied)
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


def _scratch(match: MatchContext, robot: RobotPlan) -> LogFolder | None:
    """The robot's capped scratch space with its :data:`layout.SCRATCH_DIRS`, or None when no
    cap can be applied (the robot then gets small tmpfs folders)."""
    started = match.started
    cap = int(match.plan.limits.scratch_gb * 1e9)
    scratch = match.host.log_folder(
        match_id=match.plan.match_id, name=f"{robot.key}-scratch", cap_bytes=cap,
        fallback=match.options.out_dir / ".scratch" / robot.key,
    )
    if scratch.cap_bytes is None:
        shutil.rmtree(match.options.out_dir / ".scratch", ignore_errors=True)
        return None
    started.scratch[robot.key] = scratch
    for name in layout.SCRATCH_DIRS:
        path = scratch.path / name
        path.mkdir(exist_ok=True)
        path.chmod(0o700 if name == "root" else 0o1777)
    return scratch


class StartupPhase:
    """STARTING: networks, firewall, match spec, simulator, robots; returns what it created."""

    def __init__(self, match: MatchContext) -> None:
        self.match = match


    def run(self, started_at: float) -> Started:
        """Start everything; a robot that cannot start is recorded, a team without any fails the
        match. Returns what was created (also kept in the context for teardown)."""
        _start(self.match, started_at)
        return self.match.started


__all__ = ["StartupPhase"]
