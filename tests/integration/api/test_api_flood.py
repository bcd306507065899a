"""A robot that floods its API port with 4.4 MB ActuatorRequests, over real sockets: its
requests are dropped undecoded and counted, and the other team's robot keeps its lockstep
pace."""

from __future__ import annotations

import socket
import threading
import time

from contracts.robot_api import messages_pb2 as pb
from robot.client import RobotClient
from simulator.api import FakeDeviceWorld, LockstepSettings
from simulator.api.bounds import MAX_REQUEST_BYTES
from simulator.api.framing import encode_frame
from tests.integration.api.harness import BLUE1, RED1, Driver, running_server, wait_until

STEPS = 150


def _huge_request() -> bytes:
    request = pb.ActuatorRequests()
    position = request.motor_positions.add()
    position.name = "x" * 4_400_000
    position.position = 1.0
    return encode_frame(request.SerializeToString())


def _flood(port: int, stop: threading.Event, sent: list[int]) -> None:
    frame = _huge_request()
    with socket.create_connection(("127.0.0.1", port), timeout=5) as sock:
        assert sock.recv(8) == b"Welcome\0"
        sock.settimeout(0.5)
        while not stop.is_set():
            try:
                sock.sendall(frame)
                sent[0] += 1
            except (TimeoutError, OSError):
                continue


def _answer(client: RobotClient, steps: int) -> float:
    """Seconds the honest client takes to answer ``steps`` measurements, one step each."""
    started = time.monotonic()
    for _ in range(steps):
        msg = client.receive(timeout=10)
        client.set_positions({"Neck": msg.time / 1000.0})
    return time.monotonic() - started


def _messages_in(driver: Driver, key: str) -> int:
    return int(driver.server.statistics()[key]["messages_in"])


def test_a_flooding_robot_costs_only_itself() -> None:
    lockstep = LockstepSettings(deadline_s=0.05, time_bank_s=0.2)
    world = FakeDeviceWorld((RED1, BLUE1))
    with running_server(robots=(RED1, BLUE1), lockstep=lockstep, pause_s=0.0, world=world,
                        hold=True) as (driver, ports):
        with RobotClient("127.0.0.1", ports[BLUE1], retries=3,
                         retry_interval_s=0.1).connect() as honest:
            honest.enable("NeckS", 8)
            wait_until(lambda: driver.server.connected())
            driver.max_steps = None
            alone_s = _answer(honest, STEPS)
            stop, sent = threading.Event(), [0]
            flooder = threading.Thread(target=_flood, args=(ports[RED1], stop, sent))
            flooder.start()
            try:
                wait_until(lambda: driver.server.statistics()["red-1"]["dropped_in"], 20)
                flooded_s = _answer(honest, STEPS)
                # the last answers may still wait in the socket (measurements queued while the
                # robot was out of lockstep are answered in a burst): read before counting
                wait_until(lambda: _messages_in(driver, "blue-1") >= 2 * STEPS, 20)
            finally:
                stop.set()
                flooder.join(timeout=10)
        stats = driver.server.statistics()
    red, blue = stats["red-1"], stats["blue-1"]
    assert sent[0] >= 1 and red["dropped_in"]["size"] >= 1
    assert red["dropped_in_bytes"] >= red["dropped_in"]["size"] * 4_400_000
    assert red["messages_in"] == 0 and red["decode_errors"] == 0  # nothing of it decoded
    assert blue["dropped_in"] == {} and blue["messages_in"] >= 2 * STEPS
    # the honest robot's pace: one step per answer, with or without the flood next to it
    assert flooded_s < 3 * alone_s + 2.0, (alone_s, flooded_s)
    assert MAX_REQUEST_BYTES < 4_400_000
