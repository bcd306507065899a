"""Steady steps (every robot steady: the server builds the step without asking each session and
the I/O thread frames it) give the clients the bytes of the robot-by-robot path, through every
change that ends a steady run: a client enabling its sensors later, a warning, a second period,
a removal, a client leaving. Real world, real sockets, with the I/O thread (which frames a steady
step) and without it (the step thread sends a steady step's frames, as in plain lockstep); the step
is driven here."""

from __future__ import annotations

import socket
import time
from collections.abc import Callable
from functools import partial
from typing import Any

import pytest

from contracts.ids import RobotId, TeamColor
from contracts.match_spec import NetworkSpec
from contracts.robot_api import messages_pb2 as pb
from simulator.api import ApiServer, PlayerEndpoint
from simulator.api.endpoints import free_ports
from simulator.api.framing import HEADER, WELCOME
from simulator.api.server import ApiServer as ServerClass
from tests.integration.api.harness import local_server, real_world, wait_until

ROBOTS = (RobotId(TeamColor.RED, 1), RobotId(TeamColor.RED, 2), RobotId(TeamColor.BLUE, 1))
JOINTS = ("NeckS", "HeadS", "AnkleLS", "AnkleRS", "LegUpperLS")


def _frame(request: pb.ActuatorRequests) -> bytes:
    payload: bytes = request.SerializeToString()
    return HEADER.pack(len(payload)) + payload


def _enable(periods: dict[str, int]) -> bytes:
    request = pb.ActuatorRequests()
    for name, period in periods.items():
        request.sensor_time_steps.add(name=name, timeStep=period)
    return _frame(request)


def _unknown_motor() -> bytes:
    request = pb.ActuatorRequests()
    request.motor_positions.add(name="NoSuchMotor", position=0.1)
    return _frame(request)


def _frames(data: bytes) -> list[bytes]:
    out, at = [], 0
    while at + HEADER.size <= len(data):
        (size,) = HEADER.unpack(data[at : at + HEADER.size])
        out.append(data[at + HEADER.size : at + HEADER.size + size])
        at += HEADER.size + size
    assert at == len(data), "a partial frame at the end"
    return out


def _connected(server: ApiServer, robot: RobotId, connected: bool = True) -> bool:
    """Serve the server's sockets once; whether ``robot`` has (or has no) client now."""
    server.poll(0.01)
    return (server.connection(robot) is not None) is connected


def _send_read(server: ApiServer, robot: RobotId, sock: socket.socket, frame: bytes) -> None:
    """Send one request and wait until the server has read it (queued, or posted on the
    target board: :mod:`simulator.api.board`)."""
    conn = server.connection(robot)
    assert conn is not None
    read = conn.stats.messages_in
    sock.sendall(frame)
    if server._sender is None:  # the step thread reads: serve the sockets meanwhile
        wait_until(lambda: server.poll(0.001) or conn.stats.messages_in > read)
    else:
        wait_until(lambda: conn.stats.messages_in > read)


class _Client:
    def __init__(self, port: int) -> None:
        self.sock = socket.create_connection(("127.0.0.1", port), timeout=5.0)
        self.received = bytearray()

    def welcome(self) -> None:
        assert self.sock.recv(8, socket.MSG_WAITALL) == WELCOME

    def drain(self) -> None:
        self.sock.settimeout(0.3)
        try:
            while chunk := self.sock.recv(1 << 16):
                self.received += chunk
        except TimeoutError:
            pass


def _play(steady: bool, real_time_at: int = 1_700_000_000_000, threaded: bool = True) -> tuple[
    dict[RobotId, list[bytes]], int
]:
    """The scenario, in async stepping with the I/O thread (``threaded``) or without it; the
    frames each client received and the number of steps built robot by robot. The real time is
    ``real_time_at`` plus the world's time (both runs give the same bytes)."""
    world = real_world(ROBOTS)
    server, ports = local_server(world, ROBOTS, unix_ms=lambda: real_time_at + world.sim_time_ms,
                                 send_thread=threaded)  # fmt: skip
    built_each = 0
    each = ServerClass._prepare_each

    def counted(self: ApiServer, *args: Any) -> Any:
        nonlocal built_each
        built_each += 1
        result = each(self, *args)
        if not steady:
            self._steady_step = None
        return result

    server._prepare_each = counted.__get__(server)  # type: ignore[method-assign]
    server.start()
    clients: dict[RobotId, _Client] = {}
    try:
        for robot, port in zip(ROBOTS, ports, strict=True):
            clients[robot] = _Client(port)
            wait_until(partial(_connected, server, robot))
            clients[robot].welcome()

        def send(robot: RobotId, frame: bytes) -> None:
            _send_read(server, robot, clients[robot].sock, frame)

        red1, red2, blue1 = ROBOTS
        actions: dict[int, Callable[[], None]] = {
            2: lambda: send(red1, _enable(dict.fromkeys(JOINTS, 8))),
            3: lambda: send(blue1, _enable({"Gyro": 8, "Accelerometer": 8})),
            5: lambda: send(red2, _enable(dict.fromkeys(JOINTS[:2], 8))),  # a later start
            15: lambda: send(red2, _unknown_motor()),  # a warning in one measurement
            20: lambda: send(blue1, _enable({"NeckS": 16})),  # a second period
            26: lambda: send(blue1, _enable({"NeckS": 0})),  # steady again
            30: lambda: world.removed.__setitem__(world.index.by_id[red1].number, True),
            34: lambda: world.removed.__setitem__(world.index.by_id[red1].number, False),
            36: lambda: send(red1, _enable(dict.fromkeys(JOINTS, 8))),
            45: lambda: clients.pop(blue1).sock.close(),
        }
        for step in range(60):
            if step in actions:
                actions[step]()
            if step == 46:
                wait_until(lambda: _connected(server, blue1, connected=False))
            server.apply_requests(world.sim_time_ms + world.step_ms)
            world.step()
            world.snapshot()
            server.publish(world.sim_time_ms)
            if not threaded:
                server.poll(0.0)  # (the step thread writes what a socket did not take)
        time.sleep(0.2)
        for client in clients.values():
            client.drain()
        return {r: _frames(bytes(c.received)) for r, c in clients.items()}, built_each
    finally:
        for client in clients.values():
            client.sock.close()
        server.close()


@pytest.mark.parametrize(
    "real_time_at",
    [
        1_700_000_000_000,
        # the real time needs a seventh varint byte from step 41 on (sim time 336 ms), in a
        # steady stretch: the measurement's head grows by a byte while the robots stay steady
        2**42 - 330,
    ],
    ids=["same-head", "head-grows"],
)
@pytest.mark.parametrize("threaded", [True, False], ids=["io-thread", "step-thread"])
def test_steady_steps_give_the_robot_by_robot_bytes(real_time_at: int, threaded: bool) -> None:
    steady, built_steady = _play(steady=True, real_time_at=real_time_at, threaded=threaded)
    each, built_each = _play(steady=False, real_time_at=real_time_at, threaded=threaded)
    assert built_each == 60  # the reference: every step robot by robot
    assert 60 - built_steady >= 20  # steady steps in every quiet stretch
    assert steady.keys() == each.keys() and len(steady) == 2  # blue 1 left
    for robot, frames in steady.items():
        assert len(frames) == 60
        assert frames == each[robot], robot
    red1, red2 = steady[ROBOTS[0]], steady[ROBOTS[1]]
    parsed = [pb.SensorMeasurements.FromString(f) for f in red2]
    assert [m.time for m in parsed] == [8 * (k + 1) for k in range(60)]
    assert [m.real_time for m in parsed] == [real_time_at + 8 * (k + 1) for k in range(60)]
    assert sum(1 for m in parsed if m.messages) == 1  # the warning, once
    assert len(parsed[-1].position_sensors) == 2
    removed = [pb.SensorMeasurements.FromString(f) for f in red1[30:34]]
    assert all(not m.position_sensors for m in removed)
    assert len(pb.SensorMeasurements.FromString(red1[-1]).position_sensors) == len(JOINTS)


def test_a_real_worlds_limp_flags_hold_and_release_the_targets() -> None:
    """The server follows the world's limp list (one comparison a step when nothing changed):
    targets sent while limp are kept, not applied, and applied on release."""
    from referee.snapshot import SetLimp

    robot = ROBOTS[0]
    world = real_world([robot])
    (port,) = free_ports(1)
    server = ApiServer(
        world=world,
        endpoints=[PlayerEndpoint(robot=robot, port=port, hosts=("127.0.0.1",), team_size=4)],
        network=NetworkSpec(api_bind_host="127.0.0.1"),
    )
    server.start()
    client = _Client(port)
    neck = int(world.motor_targets_plan(robot, ("Neck",))[0])

    def step_with(position: float | None) -> None:
        if position is not None:
            request = pb.ActuatorRequests()
            request.motor_positions.add(name="Neck", position=position)
            _send_read(server, robot, client.sock, _frame(request))
        server.apply_requests(world.sim_time_ms + world.step_ms)
        world.step()
        server.publish(world.sim_time_ms)

    try:
        wait_until(lambda: _connected(server, robot))
        client.welcome()
        for _ in range(3):
            step_with(0.5)
        assert world.motors.target[neck] == 0.5
        world.apply(SetLimp(robot=robot, limp=True))
        for _ in range(3):
            step_with(-0.4)
        assert world.motors.target[neck] == 0.5  # limp: kept, not applied
        step_with(None)
        world.apply(SetLimp(robot=robot, limp=False))
        step_with(None)
        assert world.motors.target[neck] == -0.4  # released: the latest target
        step_with(0.2)
        assert world.motors.target[neck] == 0.2
    finally:
        client.sock.close()
        server.close()
