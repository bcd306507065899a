"""Plain lockstep's exchange thread (``simulator.api.exchange``): the same match, step for step,
with it and without it. Real world, real sockets, three clients in threads that answer every
measurement, through what the thread must hand back to the step thread's reads: two requests
in one answer, a request whose length and body come in two writes without ``TCP_NODELAY`` (as
the league's client writes), another name list, an empty request, a target that is not a
number, an unknown motor, a late answer, a client that leaves. The world's motor targets after
every step's requests and every byte each client received must be the same both ways."""

from __future__ import annotations

import math
import socket
import threading
import time
from functools import partial

import numpy as np
import pytest

from contracts.ids import RobotId, TeamColor
from contracts.robot_api import messages_pb2 as pb
from simulator.api import ApiServer, LockstepSettings, stepping_for
from simulator.api.framing import HEADER, WELCOME
from tests.integration.api.harness import local_server, real_world, wait_until

pytestmark = pytest.mark.xdist_group("timing")

ROBOTS = (RobotId(TeamColor.RED, 1), RobotId(TeamColor.RED, 2), RobotId(TeamColor.BLUE, 1))
MOTORS = ("Neck", "Head", "AnkleL", "AnkleR", "LegUpperL")
STEPS = 80
LEAVES_AT = 64  # the third client closes after answering this many measurements
LOCKSTEP = LockstepSettings(deadline_s=5.0, time_bank_s=10.0)  # nobody is late here


def _frame(request: pb.ActuatorRequests) -> bytes:
    payload: bytes = request.SerializeToString()
    return HEADER.pack(len(payload)) + payload


def _targets(names: tuple[str, ...], step: int, robot: int, bad: bool = False) -> bytes:
    request = pb.ActuatorRequests()
    for i, name in enumerate(names):
        value = 0.3 * math.sin(0.2 * step + i + robot) + 0.05
        request.motor_positions.add(name=name, position=math.nan if bad and i == 1 else value)
    return _frame(request)


def _enable() -> bytes:
    request = pb.ActuatorRequests()
    for name in ("Gyro", "Accelerometer", "NeckS"):
        request.sensor_time_steps.add(name=name, timeStep=8)
    return _frame(request)


def _unknown_motor() -> bytes:
    request = pb.ActuatorRequests()
    request.motor_positions.add(name="NoSuchMotor", position=0.1)
    return _frame(request)


def _answers(robot: int, step: int) -> list[bytes | float]:
    """What client ``robot`` writes after its ``step``-th measurement: frames (each in one
    write), or a pause in seconds between two writes."""
    usual = _targets(MOTORS, step, robot)
    if robot == 0 and step == 20:
        return [usual + _targets(MOTORS, step + 100, robot)]  # two requests in one write
    if robot == 1 and step in (25, 26, 27):
        return [usual[: HEADER.size], 0.003, usual[HEADER.size :]]  # length, then body
    if robot == 2 and 30 <= step < 34:
        return [_targets(MOTORS[:3], step, robot)]  # another name list, then back
    if robot == 0 and step == 38:
        return [HEADER.pack(0)]  # an empty request: an answer with nothing to apply
    if robot == 1 and step == 42:
        return [_targets(MOTORS, step, robot, bad=True)]  # a target that is not a number
    if robot == 2 and step == 46:
        return [_unknown_motor()]
    if robot == 0 and step == 50:
        return [0.02, usual]  # late
    return [usual]


def _read_frame(sock: socket.socket) -> bytes:
    head = sock.recv(HEADER.size, socket.MSG_WAITALL)
    if len(head) < HEADER.size:
        return b""
    (size,) = HEADER.unpack(head)
    return head + (sock.recv(size, socket.MSG_WAITALL) if size else b"")


def _client(port: int, robot: int, received: list[bytes]) -> None:
    sock = socket.create_connection(("127.0.0.1", port), timeout=10.0)
    try:
        assert sock.recv(len(WELCOME), socket.MSG_WAITALL) == WELCOME
        sock.sendall(_enable())
        for step in range(STEPS):
            frame = _read_frame(sock)
            if not frame:
                return
            received.append(frame)
            if robot == 2 and step == LEAVES_AT:
                return
            for part in _answers(robot, step):
                if isinstance(part, float):
                    time.sleep(part)
                else:
                    sock.sendall(part)
    finally:
        sock.close()


def _all_connected(server: ApiServer, count: int) -> bool:
    server.poll(0.005)
    return len(server.connected()) == count


def _play(exchange: bool) -> tuple[list[np.ndarray], list[list[bytes]], dict[str, int] | None]:
    """The scenario: the world's motor targets after each step's requests, what each client
    received, and the exchange thread's figures."""
    world = real_world(ROBOTS)
    server, ports = local_server(world, ROBOTS, lockstep=LOCKSTEP, exchange=exchange,
                                 unix_ms=lambda: 1_700_000_000_000)  # fmt: skip
    server.start()
    received: list[list[bytes]] = [[] for _ in ROBOTS]
    clients = [threading.Thread(target=_client, args=(port, k, received[k]), daemon=True)
               for k, port in enumerate(ports)]  # fmt: skip
    targets = []
    try:
        for client in clients:
            client.start()
        wait_until(partial(_all_connected, server, len(ROBOTS)))
        stepping = stepping_for("lockstep", server, LOCKSTEP)
        for _ in range(STEPS):
            stepping.before_step(world.sim_time_ms, world.sim_time_ms + world.step_ms)
            targets.append(world.motors.target.copy())
            world.step()
            stepping.after_step(world.sim_time_ms)
        figures = server.exchange_figures
    finally:
        server.close()
        for client in clients:
            client.join(timeout=10.0)
    return targets, received, figures


def test_the_exchange_thread_plays_the_step_thread_s_match() -> None:
    threaded, received, figures = _play(exchange=True)
    own, own_received, none = _play(exchange=False)
    assert none is None
    assert figures is not None, "no exchange thread here (a C compiler is needed)"
    # most steps went through the thread; each irregular answer was handed back and read here
    assert figures["steps"] >= STEPS // 2
    assert figures["taken"] >= 2 * figures["steps"]
    assert figures["handed_back"] >= 4
    assert len(threaded) == len(own) == STEPS
    for step, (mine, theirs) in enumerate(zip(threaded, own, strict=True)):
        assert np.array_equal(mine, theirs, equal_nan=True), f"step {step}"
    assert not np.array_equal(own[10], own[11])  # the clients moved the motors
    for robot, (mine_frames, their_frames) in enumerate(zip(received, own_received, strict=True)):
        assert len(mine_frames) == len(their_frames) >= LEAVES_AT, f"robot {robot}"
        assert mine_frames == their_frames, f"robot {robot}"


def test_the_exchange_counts_what_it_sent_and_read() -> None:
    """The statistics of a match through the exchange thread equal the step thread's own: every
    measurement sent and its bytes, every request read and its bytes, a round trip per answer."""
    counts = {}
    for exchange in (True, False):
        world = real_world(ROBOTS[:2])
        server, ports = local_server(world, ROBOTS[:2], lockstep=LOCKSTEP, exchange=exchange,
                                     unix_ms=lambda: 1_700_000_000_000)  # fmt: skip
        server.start()
        received: list[list[bytes]] = [[], []]
        clients = [threading.Thread(target=_client, args=(port, k + 3, received[k]), daemon=True)
                   for k, port in enumerate(ports)]  # fmt: skip
        try:
            for client in clients:
                client.start()
            wait_until(partial(_all_connected, server, 2))
            stepping = stepping_for("lockstep", server, LOCKSTEP)
            for _ in range(40):
                stepping.before_step(world.sim_time_ms, world.sim_time_ms + world.step_ms)
                world.step()
                stepping.after_step(world.sim_time_ms)
            stepping.before_step(world.sim_time_ms, world.sim_time_ms + world.step_ms)
            stats = server.statistics()
        finally:
            server.close()
            for client in clients:
                client.join(timeout=10.0)
        counts[exchange] = [
            (s["messages_out"], s["bytes_out"], s["messages_in"], s["bytes_in"],
             s["round_trip_samples"], s["reply_samples"])
            for s in stats.values()
        ]  # fmt: skip
    assert counts[True] == counts[False]
    # a measurement a step, and its answer with its round trip, besides the enabling request
    assert all(out == 40 and answers == 41 and trips == 40 and replies == 40
               for out, _, answers, _, trips, replies in counts[True])  # fmt: skip
