"""``python -m benchmarks api``: real-time factor of the world with the robot API in use.

Starts the world and the API server in this process and N client processes (one per robot)
that enable every joint sensor and the IMU at 8 ms (and the camera when asked) and send 20
joint targets for every measurement (pre-encoded, measurements are framed but not decoded: the
clients share the machine's cores with the server being measured). Prints one JSON line with
the API run's real-time factor, the world-only real-time factor of the same world
(``World.step`` + ``snapshot``, what ``bench sim`` measures) and their ratio.
``--stalled-client`` adds a run in which one more client connects and never reads, and reports
both runs. ``--client league`` runs clients written like the league's own test client (each
request's length and body in two writes, no ``TCP_NODELAY``: :mod:`testkit.league_client`) and
reports their requests per second and round trips seen from both ends (``league_client``).
``--client one-process`` serves every robot from one client process
(:mod:`benchmarks.api_clients`) instead of one process per robot. ``--native`` runs the bench
or league clients as compiled code (:mod:`benchmarks.native_clients`), which the report's
lockstep runs use: Python clients sharing the bench machine's CPUs hold a lockstep server back
by their own cost.
``--flood`` adds two runs, the last robot standing without a client and then flooding its port
with small valid requests, and reports the other robots' real-time factor and round trip with
the flood against without (``flood``).

Without cameras, on a machine with two or more CPUs, the step thread runs on CPU 0 in every
measurement (the world-only and ``bench sim`` figures too) and the client processes on the
others, as robot code runs on its own computers in the virtual league; ``--shared-cpus`` lets
them share every CPU. (With cameras everything shares: the render thread needs a CPU too.)
With the clients on CPUs of their own, ``neighbour_cost`` gives the world's step timed with the
clients' first CPU busy against idle, before the run (:mod:`testkit.neighbour`): about 1, unless
the two CPUs share a physical core at the time, which slows a pipelined run by a quarter.
"""

from __future__ import annotations

import argparse
import json
import math
import multiprocessing as mp
import os
import socket
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, Any

# imported here, before the clients fork: a forked child importing it could wait forever on an
# import lock that one of the server's threads held at the fork
from benchmarks import api_clients, native_clients
from contracts.ids import TeamColor
from testkit import neighbour
from testkit.figures import FLOOD_TARGET, TARGETS, judged

if TYPE_CHECKING:
    from contracts.ids import RobotId

MOTORS = (
    "Neck", "Head", "ShoulderL", "ArmUpperL", "ArmLowerL", "PelvYL", "PelvL", "LegUpperL",
    "LegLowerL", "AnkleL", "FootL", "PelvYR", "PelvR", "LegUpperR", "LegLowerR", "AnkleR",
    "FootR", "ShoulderR", "ArmUpperR", "ArmLowerR",
)  # fmt: skip
CYCLE_STEPS = 125  # pre-encoded requests of the bench clients: one second of targets
INTERLEAVE_MS = 250  # simulated time per chunk of the API run and of the reference world
WARMUP_STEPS = 50  # untimed steps first, of the API run and of its reference world alike:
# sensors enabled, caches hot, the robots settled


def _parser() -> argparse.ArgumentParser:
    program = os.environ.get("HLVS_PROG", "python -m simulator")
    parser = argparse.ArgumentParser(prog=f"{program} bench api")
    parser.add_argument("--robots", type=int, default=8, help="connected clients (default 8)")
    parser.add_argument("--mode", choices=("lockstep", "pipelined", "async"), default="lockstep",
                        help="stepping mode (default lockstep; pipelined: the clients answer "
                        "while the next step is computed)")
    parser.add_argument("--camera", default="", help="WxH@PERIOD, e.g. 320x240@32")
    parser.add_argument("--sim-seconds", type=float, default=10.0,
                        help="simulated seconds to run (default 10)")
    parser.add_argument("--physics-dt", type=float, default=0.002,
                        help="physics step in seconds (default 0.002)")
    parser.add_argument(
        "--camera-robots", type=int, default=0, help="robots that enable the camera (0 = all)"
    )
    parser.add_argument(
        "--render-processes", type=int, default=-1,
        help="camera render processes (0: a thread; default: as a match chooses, one per CPU "
        "when the cameras render on the CPU)"
    )
    parser.add_argument(
        "--client", choices=("bench", "one-process", "league"), default="bench",
        help="bench: framed requests in one write, TCP_NODELAY, one process per robot "
        "(default); one-process: the same, every robot's client in one process; league: "
        "written like the league's test client (length and body in two writes, no "
        "TCP_NODELAY, one process per robot)",
    )
    parser.add_argument(
        "--native", action="store_true",
        help="--client bench or league: the clients compiled from C (built once with the "
        "machine's C compiler), so that their own cost holds the server back less",
    )
    parser.add_argument(
        "--think-ms", type=float, default=0.0,
        help="--client league: milliseconds each client takes to answer (default 0)",
    )
    parser.add_argument(
        "--flood", action="store_true",
        help="two more runs: the last robot without a client, then flooding its port with small "
        "valid requests; reports the other robots' figures with the flood against without",
    )
    parser.add_argument("--stalled-client", action="store_true",
                        help="one more client that connects and never reads")
    parser.add_argument(
        "--shared-cpus",
        action="store_true",
        help="clients share the step thread's CPU (default: CPU 0 is the step thread's)",
    )
    parser.add_argument("--gpu", choices=("auto", "on", "off"), default="auto",
                        help="cameras on an NVIDIA GPU through EGL: auto (default) when this "
                        "host has one, on: required, off: OSMesa on the CPU; a MUJOCO_GL set in "
                        "the environment is kept")
    parser.add_argument("--sensors", choices=("league", "ideal"), default="league",
                        help="league: sensor noise and camera model as in a match (default); "
                        "ideal: exact sensors and images")
    parser.add_argument("--prefetch", choices=("on", "off"), default="off",
                        help="lockstep: the next step's position stage computed on a worker "
                        "thread while the step waits for the answers (default off, as a match)")
    parser.add_argument("--exchange", choices=("auto", "on", "off"), default="auto",
                        help="plain lockstep: the steady steps' sends and reads on the compiled "
                        "exchange thread while the step thread computes the next position stage "
                        "(default auto: where it can run, as a match)")
    parser.add_argument("--json", action="store_true", help="print only the JSON line")
    return parser


def _choose_gl(mode: str) -> None:
    """``MUJOCO_GL`` of this process before MuJoCo is imported, as the simulator of a match
    chooses it (:func:`simulator.gl.select_match_gl`): EGL when this host has an NVIDIA GPU
    that renders (``--gpu``), else OSMesa."""
    if "MUJOCO_GL" in os.environ:
        return
    from orchestrator.engine.gpu import device_files
    from simulator.errors import GpuRenderError
    from simulator.gl import GPU_ENVIRONMENT, select_match_gl

    if mode == "on" or (mode == "auto" and device_files()):
        os.environ.update({GPU_ENVIRONMENT: mode, "MUJOCO_GL": "egl", "PYOPENGL_PLATFORM": "egl"})
    try:
        select_match_gl()
    except GpuRenderError as exc:
        raise SystemExit(str(exc)) from None


def _connect(port: int) -> socket.socket:
    """Connect with retries (the server may still be starting) and take the greeting."""
    from simulator.api.framing import WELCOME

    for _ in range(240):
        try:
            sock = socket.create_connection(("127.0.0.1", port), timeout=30.0)
        except OSError:
            time.sleep(0.25)
            continue
        greeting = b""
        while len(greeting) < 8:
            chunk = sock.recv(8 - len(greeting))
            if not chunk:
                break
            greeting += chunk
        if greeting == WELCOME:
            sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
            sock.settimeout(None)
            return sock
        sock.close()
        time.sleep(0.25)
    raise SystemExit(f"bench client: no session on port {port}")


def _frame(request: Any) -> bytes:
    payload: bytes = request.SerializeToString()
    return len(payload).to_bytes(4, "big") + payload


def _enable(camera_period: int) -> Any:
    """The request that enables every joint sensor and the IMU at 8 ms (and the camera)."""
    from contracts.robot_api import messages_pb2 as pb

    enable = pb.ActuatorRequests()
    periods = {f"{m}S": 8 for m in MOTORS} | {"Accelerometer": 8, "Gyro": 8}
    if camera_period:
        periods["Camera"] = camera_period
    for name, period in periods.items():
        enable.sensor_time_steps.add(name=name, timeStep=period)
    return enable


def _answers() -> list[bytes]:
    """The bench clients' framed answers: 20 joint targets, a one-second cycle."""
    from contracts.robot_api import messages_pb2 as pb

    cycle = []
    for k in range(CYCLE_STEPS):
        request = pb.ActuatorRequests()
        for i, motor in enumerate(MOTORS):
            request.motor_positions.add(name=motor, position=0.05 * math.sin(k * 0.008 + i))
        cycle.append(_frame(request))
    return cycle


def _clients(ports: list[int], camera_periods: list[int], cpus: frozenset[int]) -> None:
    """Client process body of ``--client one-process``: one process answers every robot
    (:mod:`benchmarks.api_clients`)."""
    if cpus:
        os.sched_setaffinity(0, cpus)
    socks = []
    for port, camera_period in zip(ports, camera_periods, strict=True):
        sock = _connect(port)
        sock.sendall(_frame(_enable(camera_period)))
        socks.append(sock)
    api_clients.serve_all(socks, _answers())


def _client(port: int, camera_period: int, stalled: bool, cpus: frozenset[int]) -> None:
    """Client process body of ``--client bench`` (default, one process per robot): enables the
    sensors, then answers every measurement with 20 joint targets (a 1 s cycle of pre-encoded
    requests: the bench measures the server, so the clients sharing its cores skip decoding).
    The stalled client connects, enables, and never reads."""
    if cpus:
        os.sched_setaffinity(0, cpus)

    if stalled:  # a small receive window, and it never reads: the server's queue overflows
        raw = socket.socket()
        raw.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 4096)
        for _ in range(120):
            try:
                raw.connect(("127.0.0.1", port))
                break
            except OSError:
                time.sleep(0.25)
        raw.sendall(_frame(_enable(0)))
        while True:
            time.sleep(3600)
    sock = _connect(port)
    sock.sendall(_frame(_enable(camera_period)))
    cycle = _answers()
    buffer = bytearray(1 << 20)  # received bytes land in place: no allocation per receive
    view = memoryview(buffer)
    filled = answered = 0
    try:
        while True:
            if filled == len(buffer):  # a frame larger than the buffer
                view.release()
                buffer.extend(bytes(len(buffer)))
                view = memoryview(buffer)
            received = sock.recv_into(view[filled:])
            if not received:
                break
            filled += received
            start = 0
            while filled - start >= 4:
                end = start + 4 + int.from_bytes(buffer[start : start + 4], "big")
                if end > filled:
                    break
                start = end
                sock.sendall(cycle[answered % CYCLE_STEPS])
                answered += 1
            if start:
                buffer[: filled - start] = buffer[start:filled]
                filled -= start
    except OSError:
        pass
    os._exit(0)


def _league_client(port: int, think_ms: float, cpus: frozenset[int], report: Any) -> None:
    """Client process body of ``--client league``: enables the sensors, then answers every
    measurement as the league's test client sends (the length, then the body: two writes, no
    ``TCP_NODELAY``) with the bench's 20 joint targets, after ``think_ms``. When the server
    closes, sends its medians (seconds) and count through ``report``."""
    import statistics

    from contracts.robot_api import messages_pb2 as pb
    from testkit.league_client import LeagueStyleClient

    if cpus:
        os.sched_setaffinity(0, cpus)
    for _ in range(240):
        try:
            client = LeagueStyleClient("127.0.0.1", port, timeout_s=30.0).connect()
            break
        except OSError:
            time.sleep(0.25)
    else:
        raise SystemExit(f"bench league client: no session on port {port}")
    enable = pb.ActuatorRequests()
    for name in [f"{m}S" for m in MOTORS] + ["Accelerometer", "Gyro"]:
        enable.sensor_time_steps.add(name=name, timeStep=8)
    cycle = []
    for k in range(CYCLE_STEPS):
        request = pb.ActuatorRequests()
        for i, motor in enumerate(MOTORS):
            request.motor_positions.add(name=motor, position=0.05 * math.sin(k * 0.008 + i))
        cycle.append(request.SerializeToString())
    think = (lambda: time.sleep(think_ms / 1000.0)) if think_ms > 0 else None
    answered = 0
    try:
        assert client.sock is not None
        client.sock.settimeout(None)
        client.send(enable.SerializeToString())
        while True:
            client.exchange(cycle[answered % CYCLE_STEPS], think)
            answered += 1
    except (OSError, ConnectionError):
        pass
    medians = [statistics.median(values) if values else None
               for values in (client.answer_s, client.round_trip_s)]  # fmt: skip
    report.send((answered, *medians))
    os._exit(0)


def _robots(count: int) -> list[RobotId]:
    from contracts.ids import RobotId

    red = (count + 1) // 2
    return [RobotId(TeamColor.RED, n) for n in range(1, red + 1)] + [
        RobotId(TeamColor.BLUE, n) for n in range(1, count - red + 1)
    ]


def _world(robots: list[RobotId], physics_dt: float, sensors: str = "league") -> Any:
    """The benchmark's world; ``sensors`` "league" (as a match plays: sensor noise and the
    camera model) or "ideal"."""
    from simulator.world import CameraModel, RobotPlacement, SensorModel, World

    placements = [
        RobotPlacement(
            id=r,
            model="kid-default",
            x_m=(-1.0 if r.team is TeamColor.RED else 1.0) * (0.8 + 0.8 * r.number),
            y_m=0.8 * (r.number - 2.5),
            yaw_rad=0.0 if r.team is TeamColor.RED else math.pi,
        )
        for r in robots
    ]
    league = sensors == "league"
    return World.create(
        field_class="kid", robots=placements, seed=1, physics_dt_s=physics_dt,
        sensor_model=SensorModel() if league else SensorModel.ideal(),
        camera_model=CameraModel.league(1) if league else CameraModel.ideal(),
    )  # fmt: skip


def _sensor_noise_cost(
    robots: list[RobotId], physics_dt: float, sensors: str
) -> dict[str, float] | None:
    """What the league's sensor model adds to a basic step (``World.step`` + snapshot), timed
    where it runs, right after the physics: an ideal and a league world step in alternating
    chunks of 25 steps (so the machine's load falls on both alike), 2 simulated seconds each.
    CPU microseconds per step of each and their ratio; None for ideal sensors."""
    if sensors == "ideal":
        return None
    worlds = {"ideal": _world(robots, physics_dt, "ideal"), "league": _world(robots, physics_dt)}
    cpu = dict.fromkeys(worlds, 0.0)
    for _ in range(10):
        for name, world in worlds.items():
            started = time.thread_time()
            for _ in range(25):
                world.step()
                world.snapshot()
            cpu[name] += time.thread_time() - started
    ideal_us, league_us = (cpu[name] / 250 * 1e6 for name in ("ideal", "league"))
    return {
        "ideal_us_per_step": round(ideal_us, 1),
        "league_us_per_step": round(league_us, 1),
        "ratio": round(league_us / ideal_us, 3),
    }


def _client_targets(world: Any, robots: list[RobotId]) -> Callable[[], None]:
    """The bench clients' joint targets, written into a reference world one step at a time
    (one clamped write for all robots, as the API's batch does): the reference moves its joints
    as the API run's robots do, so the physics of both costs the same (on the soft grass a
    robot moving its joints costs the solver more than a robot holding still) and the ratio is
    the server's own cost."""
    import numpy as np

    plans = [world.motor_targets_plan(r, MOTORS) for r in robots]
    writer = world.motor_targets_writer(np.concatenate(plans))
    one = [[0.05 * math.sin(k * 0.008 + i) for i in range(len(MOTORS))]
           for k in range(CYCLE_STEPS)]
    cycle = np.tile(np.asarray(one), (1, len(robots)))
    step = [0]

    def move() -> None:
        writer(cycle[step[0] % CYCLE_STEPS], finite=True)
        step[0] += 1

    return move


def _reference(
    robots: list[RobotId], physics_dt: float, sensors: str
) -> tuple[Any, Callable[[], None]]:
    """A reference world and one step of it as the API run steps its own (the clients' joint
    targets written, ``World.step``, ``snapshot``): what the API run is measured against."""
    world = _world(robots, physics_dt, sensors)
    move = _client_targets(world, robots)

    def step() -> None:
        move()
        world.step()
        world.snapshot()

    return world, step


def _world_only(
    robots: list[RobotId], physics_dt: float, sim_seconds: float, sensors: str = "league"
) -> tuple[float, float]:
    """(real-time factor, CPU seconds per simulated second) of World.step + snapshot."""
    world, step = _reference(robots, physics_dt, sensors)
    steps = int(sim_seconds * 1000 / world.step_ms)
    started, started_cpu = time.perf_counter(), time.thread_time()
    for _ in range(steps):
        step()
    simulated = steps * world.step_ms / 1000.0
    wall, cpu = time.perf_counter() - started, time.thread_time() - started_cpu
    return simulated / wall, cpu / simulated


def _render_costs(
    robots: list[RobotId], physics_dt: float, width: int, height: int, frames: int = 60
) -> dict[str, float | str]:
    """CPU ms per frame of a bare offscreen render (``mujoco.Renderer`` with the model's own
    settings, update_scene + render) against the robot camera path (:class:`CameraRenderer`:
    coarser tessellation, its shadows (``camera_shadows``: planar on a CPU renderer unless
    ``HLVS_CAMERA_SHADOWS`` says otherwise), no reflections, B,G,R bytes) on the same scene,
    from the robots' head cameras in turn. Same process, same run: the ratio is what the camera
    path adds to (or saves on) what the renderer costs."""
    import mujoco

    from simulator.world import CameraRenderer

    world = _world(robots, physics_dt)
    for _ in range(25):  # the robots settle a little: a scene as in a match
        world.step()
    cameras = [world.index.by_id[r].camera for r in robots]

    def timed(render: Any) -> float:
        render(0)  # context and caches made outside the timing
        started = time.thread_time()
        for k in range(frames):
            render(k % len(robots))
        return (time.thread_time() - started) * 1000.0 / frames

    bare = mujoco.Renderer(world.model, height=height, width=width)
    ours = CameraRenderer(world, width, height)
    try:
        def bare_frame(k: int) -> None:
            bare.update_scene(world.data, camera=cameras[k])
            bare.render()

        bare_ms = timed(bare_frame)
        ours_ms = timed(lambda k: ours.render(robots[k]))
        shadows = ours.shadows
    finally:
        bare.close()
        ours.close()
    return {
        "bare_render_ms_per_frame": round(bare_ms, 2),
        "camera_path_ms_per_frame": round(ours_ms, 2),
        "render_cost_ratio": round(ours_ms / bare_ms, 3) if bare_ms > 0 else float("nan"),
        "camera_shadows": shadows,
    }


def _neighbour_cost(args: argparse.Namespace, robots: list[RobotId]) -> dict[str, Any] | None:
    """The world's step with the clients' first CPU busy against idle
    (:mod:`testkit.neighbour`: about 1 unless the two CPUs share a physical core now), on a
    reference world before the API run; None where the clients share the step thread's CPUs."""
    if not args.client_cpus:
        return None
    _, step = _reference(robots, args.physics_dt, args.sensors)
    for _ in range(WARMUP_STEPS):
        step()
    return neighbour.cost(step, min(args.client_cpus))


def _bench_sim(robots: int, physics_dt: float, sim_seconds: float) -> dict[str, Any] | None:
    """The world's ``bench sim`` numbers for the same setup, when they are available."""
    try:
        from benchmarks.sim import run
    except ImportError:
        return None
    result = run(robots=robots, sim_seconds=sim_seconds, physics_dt_s=physics_dt, field_class="kid")
    return {k: result[k] for k in ("real_time_factor", "bare_real_time_factor") if k in result}


def _flood_client(port: int, cpus: frozenset[int]) -> None:
    """Client process body of the flooding robot (``--flood``): small valid requests without
    pause (:func:`testkit.flood_client.flood`) until killed."""
    import threading

    from testkit.flood_client import flood

    if cpus:
        os.sched_setaffinity(0, cpus)
    flood(port, threading.Event(), [0])
    os._exit(0)


def _api_run(
    args: argparse.Namespace, camera: tuple[int, int, int] | None, stalled: bool,
    last: str = "",
) -> dict[str, Any]:
    """One API run; ``last``: what the last robot's client does, "" as the others, "flood"
    (:func:`_flood_client`) or "absent" (no client: the robot stands)."""
    from contracts.match_spec import NetworkSpec
    from simulator.api import (
        ApiServer,
        LockstepSettings,
        PlayerEndpoint,
        stepping_for,
        world_cameras,
    )
    from simulator.api.endpoints import free_ports

    robots = _robots(args.robots)
    world = _world(robots, args.physics_dt, args.sensors)
    if camera is not None:
        world_camera = world.camera_info(robots[0])
        if world_camera[:2] != camera[:2]:
            raise SystemExit(f"--camera: the robot camera is {world_camera[0]}x{world_camera[1]}")
    lockstep = LockstepSettings(
        deadline_s=0.05, time_bank_s=1.0, pipelined=args.mode == "pipelined"
    )
    ports = free_ports(len(robots))
    endpoints = [
        PlayerEndpoint(robot=r, port=p, hosts=("127.0.0.1",), team_size=4)
        for r, p in zip(robots, ports, strict=True)
    ]
    stalled_robot = robots[-1] if stalled else None
    if args.render_processes < 0:
        args.render_processes = world_cameras.render_processes()
    cameras = world_cameras.world_render_worker(world, processes=args.render_processes)
    server = ApiServer(
        world=world,
        endpoints=endpoints,
        network=NetworkSpec(api_bind_host="127.0.0.1"),
        lockstep=lockstep if args.mode in ("lockstep", "pipelined") else None,
        cameras=cameras,
        send_cpus=args.client_cpus or None,
        exchange={"auto": None, "on": True, "off": False}[args.exchange],
    )
    server.start()
    ctx = mp.get_context("fork")
    camera_robots = args.camera_robots or len(endpoints)
    reports = []  # the league clients' figures, sent when the server closes
    procs = []
    together: list[tuple[int, int]] = []  # (port, camera period) of --client one-process
    natives = []  # --native: the compiled clients
    for i, e in enumerate(endpoints):
        if args.native_frames is not None and e.robot != stalled_robot and (
            not last or e.robot != robots[-1]
        ):
            camera_period = camera[2] if camera and i < camera_robots else 0
            natives.append(native_clients.start(
                args.native_program, e.port, args.native_frames[camera_period],
                _native_style(args), args.client_cpus,
            ))  # fmt: skip
            continue
        if last and e.robot == robots[-1]:
            if last == "flood":
                procs.append(ctx.Process(target=_flood_client, args=(e.port, args.client_cpus),
                                         daemon=True))  # fmt: skip
            continue
        if args.client == "league" and e.robot != stalled_robot:
            receive, send = ctx.Pipe(duplex=False)
            reports.append(receive)
            procs.append(ctx.Process(
                target=_league_client, args=(e.port, args.think_ms, args.client_cpus, send),
                daemon=True,
            ))  # fmt: skip
            continue
        camera_period = camera[2] if camera and i < camera_robots else 0
        if args.client == "one-process" and e.robot != stalled_robot:
            together.append((e.port, camera_period))
            continue
        procs.append(ctx.Process(
            target=_client,
            args=(e.port, camera_period, e.robot == stalled_robot, args.client_cpus),
            daemon=True,
        ))  # fmt: skip
    if together:  # every robot's client in one process
        ports_together, periods = (list(column) for column in zip(*together, strict=True))
        procs.append(ctx.Process(target=_clients, args=(ports_together, periods,
                                                        args.client_cpus), daemon=True))
    for proc in procs:
        proc.start()
    try:
        deadline = time.monotonic() + 120
        clients = len(endpoints) - (last == "absent")
        while len(server.connected()) < clients and time.monotonic() < deadline:
            server.poll(0.05)
        stepping = stepping_for(args.mode, server, lockstep,  # as a match's loop steps
                                prefetch=world.prefetch if args.prefetch == "on" else None)

        def one_step() -> None:
            stepping.before_step(world.sim_time_ms, world.sim_time_ms + world.step_ms)
            world.step()
            stepping.after_step(world.sim_time_ms)
            world.snapshot()  # (the match loop's referee looks at it)

        for _ in range(WARMUP_STEPS):
            one_step()
        stepping.waited_s = 0.0
        steps = int(args.sim_seconds * 1000 / world.step_ms)
        start_ms = world.sim_time_ms
        # without cameras (whose render thread would run on), chunks of a reference world
        # (World.step + snapshot, as bench sim) alternate with chunks of the API run, so that
        # the machine's load falls on both alike: ``ratio_interleaved``
        reference = None if camera is not None else _reference(robots, args.physics_dt,
                                                                 args.sensors)[1]

        def reference_steps(count: int) -> None:
            assert reference is not None
            for _ in range(count):
                reference()

        if reference is not None:
            reference_steps(WARMUP_STEPS)
        chunk = max(1, INTERLEAVE_MS // world.step_ms)
        requests_before = sum(slot.stats.messages_in for slot in server.slots.values())
        wakes_before = server.io_wakes
        requests = 0
        wall = cpu = ref_wall = ref_cpu = 0.0
        done = 0
        while done < steps:
            count = min(chunk, steps - done) if reference is not None else steps
            started, started_cpu = time.perf_counter(), time.thread_time()
            for _ in range(count):
                one_step()
            wall += time.perf_counter() - started
            cpu += time.thread_time() - started_cpu
            requests_after = sum(slot.stats.messages_in for slot in server.slots.values())
            requests += requests_after - requests_before
            done += count
            if reference is not None:
                started, started_cpu = time.perf_counter(), time.thread_time()
                reference_steps(count)
                ref_wall += time.perf_counter() - started
                ref_cpu += time.thread_time() - started_cpu
            requests_before = sum(slot.stats.messages_in for slot in server.slots.values())
        waited = stepping.waited_s
        io_wakes = server.io_wakes - wakes_before
        exchange = server.exchange_figures
        stats = server.statistics()
    finally:
        server.close()
        cameras.close()
        # the league clients' figures: (answers, answer_s median, round_trip_s median)
        league = [receive.recv() for receive in reports if receive.poll(10.0)]
        for proc in procs:
            proc.kill()
            proc.join(timeout=5)
        for native in natives:  # each ends when the server closes its socket
            league.extend(native_clients.figures(native))
    rtts = [s["round_trip_ms"]["p50"] for s in stats.values() if s["round_trip_ms"]["p50"]]
    replies = sorted(s["reply_ms"]["p50"] for s in stats.values() if s["reply_ms"]["p50"])
    last_key = robots[-1].key
    honest = [s["round_trip_ms"]["p50"] for key, s in stats.items()
              if s["round_trip_ms"]["p50"] and not (last and key == last_key)]  # fmt: skip
    league_client = None
    if args.client == "league":
        def median_ms(index: int) -> float | None:
            values = sorted(report[index] for report in league if report[index] is not None)
            return round(values[len(values) // 2] * 1000.0, 3) if values else None

        league_client = {
            "clients": len(reports) or len(natives),
            "reported": len(league),
            "think_ms": args.think_ms,
            # requests the server received per second of the API run's wall time
            "requests_per_s": round(requests / wall, 1),
            # the server's round trip: measurement sent to answer received (p50, robots' median)
            "round_trip_p50_ms": round(sorted(rtts)[len(rtts) // 2], 3) if rtts else None,
            # the client's part of it: measurement arrived to answer written
            "client_answer_p50_ms": median_ms(1),
            # the client's own wait: answer written to next measurement arrived (the step)
            "client_round_trip_p50_ms": median_ms(2),
            # the same wait seen by the server: the answer's first byte received to the next
            # measurement's last byte written (robots' median)
            "server_reply_p50_ms": replies[len(replies) // 2] if replies else None,
        }
        client_wait, server_wait = (league_client["client_round_trip_p50_ms"],
                                    league_client["server_reply_p50_ms"])
        # the server's figure over the client's: 1 when the server sees the wait the client has
        league_client["server_over_client"] = (
            round(server_wait / client_wait, 3) if client_wait and server_wait else None)
    messages_out = sum(s["messages_out"] for s in stats.values())
    return {
        # what the lockstep floor is given (--native): the reference world's wall time a step
        # and the measurements' mean body size
        "reference_step_us": ref_wall / steps * 1e6 if ref_wall else None,
        "measurement_bytes": round(sum(s["bytes_out"] for s in stats.values()) / messages_out)
        - 4 if messages_out else None,
        "steps": steps,
        "honest_round_trip_p50_ms": round(sorted(honest)[len(honest) // 2], 3) if honest else None,
        "last_robot": stats.get(last_key),
        "league_client": league_client,
        "real_time_factor": round((world.sim_time_ms - start_ms) / 1000.0 / wall, 3),
        "cpu_s_per_sim_s": cpu / ((world.sim_time_ms - start_ms) / 1000.0),
        "wait_share": round(waited / wall, 3),
        "io_wakes_per_step": round(io_wakes / steps, 3),
        # plain lockstep's exchange thread: steps it exchanged, answers it took and handed back
        "exchange": exchange,
        "ratio_interleaved": round(ref_wall / wall, 3) if ref_wall else None,
        "cpu_ratio_interleaved": round(ref_cpu / cpu, 3) if ref_cpu else None,
        "connected": len(stats),
        "dropped_out": sum(s["dropped_out"] for s in stats.values()),
        "dropped_in": sum(sum(s["dropped_in"].values()) for s in stats.values()),
        "slow_periods": sum(s["slow_periods"] for s in stats.values()),
        "round_trip_p50_ms": round(sorted(rtts)[len(rtts) // 2], 3) if rtts else None,
        "camera_frames": cameras.frames,
        "render_ms_per_frame": round(cameras.render_s * 1000 / cameras.frames, 2)
        if cameras.frames
        else None,
    }


def _flood_figures(
    args: argparse.Namespace, camera: tuple[int, int, int] | None
) -> dict[str, Any]:
    """The honest robots' figures with the last robot flooding its port beside them, against
    the same run with that robot standing without a client (run first)."""
    without = _api_run(args, camera, stalled=False, last="absent")
    flooded = _api_run(args, camera, stalled=False, last="flood")

    def ratio(a: float | None, b: float | None) -> float | None:
        return round(a / b, 3) if a and b else None

    flooder = flooded["last_robot"] or {}
    return {
        "honest_robots": args.robots - 1,
        "real_time_factor": flooded["real_time_factor"],
        "real_time_factor_without": without["real_time_factor"],
        # with / without: 1.0 when the flooding robot costs the others nothing
        "ratio": ratio(flooded["real_time_factor"], without["real_time_factor"]),
        # the same from the runs' interleaved ratios (the machine's load falls on both alike)
        "ratio_interleaved": ratio(flooded["ratio_interleaved"], without["ratio_interleaved"]),
        "round_trip_p50_ms": flooded["honest_round_trip_p50_ms"],
        "round_trip_p50_ms_without": without["honest_round_trip_p50_ms"],
        # without / with: 1.0 when the honest robots' round trip is as without the flood
        "round_trip_ratio": ratio(without["honest_round_trip_p50_ms"],
                                  flooded["honest_round_trip_p50_ms"]),  # fmt: skip
        "honest_slow_periods": flooded["slow_periods"] - flooder.get("slow_periods", 0),
        # the flooding robot: its requests taken, its bytes read, the times it was marked slow
        "flooder_messages_in": flooder.get("messages_in"),
        "flooder_bytes_in": flooder.get("bytes_in"),
        "flooder_slow_periods": flooder.get("slow_periods"),
    }


def _camera(text: str) -> tuple[int, int, int] | None:
    if not text:
        return None
    try:
        size, period = text.split("@")
        width, height = size.lower().split("x")
        return int(width), int(height), int(period)
    except ValueError:
        raise SystemExit(f"--camera {text!r}: expected WxH@PERIOD, e.g. 320x240@32") from None


def main(argv: list[str]) -> int:
    args = _parser().parse_args(argv)
    _choose_gl(args.gpu)
    os.environ.setdefault("LP_NUM_THREADS", "0")  # as the simulator process: see runtime.py
    camera = _camera(args.camera)
    robots = _robots(args.robots)
    args.client_cpus = frozenset()
    available = sorted(os.sched_getaffinity(0))
    if not args.shared_cpus and camera is None and len(available) >= 2:
        os.sched_setaffinity(0, {available[0]})  # this (the step) thread only
        args.client_cpus = frozenset(available[1:])
    with tempfile.TemporaryDirectory(prefix="hlvs-bench-api-") as work:
        args.native_frames = _native_frames(args, camera, Path(work))
        world_rtf, world_cpu = _world_only(
            robots, args.physics_dt, min(args.sim_seconds, 10.0), args.sensors
        )
        result = _measure(args, camera, robots, world_rtf, world_cpu)
    print(json.dumps(result, sort_keys=True), flush=True)
    return 0


def _native_frames(
    args: argparse.Namespace, camera: tuple[int, int, int] | None, work: Path
) -> dict[int, Path] | None:
    """``--native``: the compiled client (built now if needed) and its frames files in ``work``,
    by camera period; None without ``--native``."""
    if not args.native:
        return None
    if args.client not in ("bench", "league"):
        raise SystemExit(f"--native: runs --client bench or league, not {args.client}")
    from simulator.api.framing import WELCOME

    args.native_program = native_clients.binary()
    frames = {}
    for period in {0, camera[2] if camera else 0}:
        folder = work / str(period)
        folder.mkdir()
        frames[period] = native_clients.frames_file(
            folder, WELCOME, _frame(_enable(period)), _answers()
        )
    return frames


def _native_style(args: argparse.Namespace) -> str:
    """The compiled clients' way of writing (:data:`benchmarks.native_clients.STYLES`)."""
    return "league" if args.client == "league" else "framed"


def _lockstep_floor(args: argparse.Namespace, api: dict[str, Any]) -> dict[str, Any]:
    """``--native`` lockstep: the serial floor on this machine with the same clients
    (:func:`benchmarks.native_clients.lockstep_floor`), its server on the step thread's CPU,
    a busy loop of the reference world's step; ``of_floor``: the API run's interleaved ratio
    over the floor's."""
    step_cpus = sorted(os.sched_getaffinity(0))
    floor = native_clients.lockstep_floor(
        args.native_frames[0], _native_style(args),
        robots=args.robots, step_us=api["reference_step_us"],
        measurement_bytes=api["measurement_bytes"], steps=api["steps"],
        server_cpu=step_cpus[0] if args.client_cpus else None, client_cpus=args.client_cpus,
    )  # fmt: skip
    if "ratio" in floor and api["ratio_interleaved"]:
        floor["of_floor"] = round(api["ratio_interleaved"] / floor["ratio"], 3)
    return floor


def _measure(
    args: argparse.Namespace, camera: tuple[int, int, int] | None, robots: list[RobotId],
    world_rtf: float, world_cpu: float,
) -> dict[str, Any]:
    """The API runs asked for, and their figures against the world's alone."""
    neighbour_cost = _neighbour_cost(args, robots)
    api = _api_run(args, camera, stalled=False)
    result: dict[str, Any] = {
        "bench": "api",
        "robots": args.robots,
        "mode": args.mode,
        "camera": args.camera or None,
        "sim_seconds": args.sim_seconds,
        "physics_dt_s": args.physics_dt,
        "sensors": args.sensors,
        "real_time_factor": api["real_time_factor"],
        "world_only_real_time_factor": round(world_rtf, 3),
        "ratio": round(api["real_time_factor"] / world_rtf, 3),
        # load-independent: simulator-thread CPU per simulated second, world only vs with the API
        "cpu_ratio": round(world_cpu / api["cpu_s_per_sim_s"], 3),
        # the step thread's CPU per simulated second in the API run (compare --sensors runs)
        "cpu_s_per_sim_s": round(api["cpu_s_per_sim_s"], 4),
        "sensor_noise_cost": _sensor_noise_cost(robots, args.physics_dt, args.sensors),
        # the same, with the world-only chunks interleaved with the API run's (no cameras)
        "ratio_interleaved": api["ratio_interleaved"],
        "cpu_ratio_interleaved": api["cpu_ratio_interleaved"],
        "bench_sim": _bench_sim(args.robots, args.physics_dt, min(args.sim_seconds, 5.0)),
        "round_trip_p50_ms": api["round_trip_p50_ms"],
        "camera_frames": api["camera_frames"],
        "camera_robots": (args.camera_robots or args.robots) if camera else 0,
        "render_ms_per_frame": api["render_ms_per_frame"],
        "render_processes": args.render_processes,
        "slow_periods": api["slow_periods"],
        # requests over the clients' bounds (simulator.api.bounds): 0 for well-behaved clients
        "dropped_in": api["dropped_in"],
        # share of the API run's wall time the step thread waited for the clients (lockstep)
        "client_wait_share": api["wait_share"],
        # wake-ups of the I/O thread the step thread paid for (a pipe write each), per step
        "io_wakes_per_step": api["io_wakes_per_step"],
        "exchange": api["exchange"],
        # the step's CPU time with the clients' CPU busy over idle, before the run: a quarter
        # or more above 1 when the two virtual CPUs share a core (testkit.neighbour)
        "neighbour_cost": neighbour_cost,
        "step_thread_cpus": sorted(os.sched_getaffinity(0)),
        "client_cpus": sorted(args.client_cpus) or "shared",
        "client": args.client,
        "native_clients": args.native,
    }
    if args.native_frames is not None and args.mode == "lockstep" and api["reference_step_us"]:
        result["lockstep_floor"] = _lockstep_floor(args, api)
    if api["league_client"] is not None:  # judged against the mode's target, as the report does
        league = dict(api["league_client"], ratio_interleaved=api["ratio_interleaved"])
        league.update(judged(TARGETS[args.mode], league))
        result["league_client"] = league
    if camera is not None:  # the camera path against a bare render of the same scene
        from simulator.gl import read_gl_info

        result.update(_render_costs(robots, args.physics_dt, camera[0], camera[1]))
        result.update(read_gl_info().record())  # gl_backend, gl_renderer: llvmpipe is the CPU
    if args.stalled_client:
        stalled = _api_run(args, camera, stalled=True)
        result["stalled_client"] = {
            "real_time_factor": stalled["real_time_factor"],
            "real_time_factor_without": api["real_time_factor"],
            "ratio": round(stalled["real_time_factor"] / api["real_time_factor"], 3),
            # step-thread CPU per simulated second without / with the stalled client
            "cpu_ratio": round(api["cpu_s_per_sim_s"] / stalled["cpu_s_per_sim_s"], 3),
            "dropped_out": stalled["dropped_out"],
        }
    if args.flood:
        flood = _flood_figures(args, camera)
        flood.update(judged(FLOOD_TARGET, flood))
        result["flood"] = flood
    return result


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
