"""The target board (the I/O thread posts every robot's usual targets, the step thread writes them
in one call) gives the world the motor targets of the robot-by-robot path, step by step, through
everything that ends it: a robot that sends nothing for a while, another name list, an unknown
motor, a robot made limp and released, a robot removed and back, a client leaving. Real world,
real sockets, with the I/O thread and without it (the step thread reads and posts, as in plain
lockstep); the step is driven here."""

from __future__ import annotations

import socket
import time
from collections.abc import Callable
from functools import partial
from typing import Any

import numpy as np
import pytest

from contracts.ids import RobotId, TeamColor
from contracts.robot_api import messages_pb2 as pb
from referee.snapshot import SetLimp
from simulator.api import ApiServer
from simulator.api.board import TargetBoard
from simulator.api.framing import HEADER, WELCOME
from tests.integration.api.harness import local_server, real_world, wait_until

ROBOTS = (RobotId(TeamColor.RED, 1), RobotId(TeamColor.RED, 2), RobotId(TeamColor.BLUE, 1))
MOTORS = ("Neck", "Head", "AnkleL", "AnkleR", "LegUpperL")
STEPS = 70


def _frame(request: pb.ActuatorRequests) -> bytes:
    payload: bytes = request.SerializeToString()
    return HEADER.pack(len(payload)) + payload


def _targets(names: tuple[str, ...], step: int, robot: int) -> bytes:
    request = pb.ActuatorRequests()
    for i, name in enumerate(names):
        request.motor_positions.add(name=name, position=0.3 * np.sin(0.2 * step + i + robot))
    return _frame(request)


def _unknown_motor() -> bytes:
    request = pb.ActuatorRequests()
    request.motor_positions.add(name="NoSuchMotor", position=0.1)
    return _frame(request)


def _connected(server: ApiServer, robot: RobotId, connected: bool = True) -> bool:
    server.poll(0.01)
    return (server.connection(robot) is not None) is connected


def _play(board: bool, threaded: bool = True) -> tuple[list[np.ndarray], int]:
    """The scenario, with the I/O thread reading the requests (``threaded``) or the step thread
    (as in plain lockstep); the world's motor targets after each step's requests are applied,
    and the number of steps the board wrote."""
    world = real_world(ROBOTS)
    server, ports = local_server(world, ROBOTS, send_thread=threaded)
    if not board:
        server._arm_board = lambda *args: None  # type: ignore[method-assign]
    written = 0
    apply = TargetBoard.apply

    def counted(self: TargetBoard, lock: Any) -> bool:
        nonlocal written
        done = apply(self, lock)
        written += done
        return done

    TargetBoard.apply = counted  # type: ignore[method-assign]
    server.start()
    socks: dict[RobotId, socket.socket] = {}
    try:
        for robot, port in zip(ROBOTS, ports, strict=True):
            socks[robot] = socket.create_connection(("127.0.0.1", port), timeout=5.0)
            wait_until(partial(_connected, server, robot))
            assert socks[robot].recv(8, socket.MSG_WAITALL) == WELCOME

        def send(robot: RobotId, frame: bytes) -> None:
            conn = server.connection(robot)
            assert conn is not None
            read = conn.stats.messages_in
            socks[robot].sendall(frame)
            if threaded:
                wait_until(lambda: conn.stats.messages_in > read)
            else:  # the step thread reads: serve the sockets meanwhile
                wait_until(lambda: server.poll(0.001) or conn.stats.messages_in > read)

        red1, red2, blue1 = ROBOTS
        number = {robot: world.index.by_id[robot].number for robot in ROBOTS}
        names: dict[RobotId, tuple[str, ...]] = dict.fromkeys(ROBOTS, MOTORS)
        # silent while limp: the release re-applies the targets the board wrote last
        silent = {(red2, k) for k in (*range(12, 16), *range(32, 38))}
        events: dict[int, Callable[[], None]] = {
            20: lambda: names.__setitem__(blue1, MOTORS[:3]),  # another name list
            26: lambda: send(red1, _unknown_motor()),  # a warning: another kind of request
            32: lambda: world.apply(SetLimp(robot=red2, limp=True)),
            36: lambda: world.apply(SetLimp(robot=red2, limp=False)),
            44: lambda: world.removed.__setitem__(number[blue1], True),
            47: lambda: world.removed.__setitem__(number[blue1], False),
            58: lambda: socks.pop(red1).close(),
        }
        targets = []
        for step in range(STEPS):
            if step in events:
                events[step]()
            if step == 59:
                wait_until(lambda: _connected(server, red1, connected=False))
            for k, robot in enumerate(ROBOTS):
                if robot in socks and (robot, step) not in silent:
                    send(robot, _targets(names[robot], step, k))
            if step % 9 == 4:  # two requests in one step: the later one wins
                send(blue1, _targets(names[blue1], step + 100, 2))
            server.apply_requests(world.sim_time_ms + world.step_ms)
            targets.append(world.motors.target.copy())
            world.step()
            server.publish(world.sim_time_ms)
        time.sleep(0.05)
        return targets, written
    finally:
        TargetBoard.apply = apply  # type: ignore[method-assign]
        for sock in socks.values():
            sock.close()
        server.close()


@pytest.mark.parametrize("threaded", [True, False], ids=["io-thread", "step-thread"])
def test_the_board_gives_the_world_the_robot_by_robot_targets(threaded: bool) -> None:
    with_board, written = _play(board=True, threaded=threaded)
    each, never = _play(board=False, threaded=threaded)
    assert never == 0  # the reference: every step robot by robot
    assert written >= 30  # the board wrote in every quiet stretch
    assert len(with_board) == len(each) == STEPS
    for step, (mine, theirs) in enumerate(zip(with_board, each, strict=True)):
        assert np.array_equal(mine, theirs), f"step {step}"
    # the scenario moved the motors: the comparison is not of constant targets
    assert not np.array_equal(each[10], each[11])
