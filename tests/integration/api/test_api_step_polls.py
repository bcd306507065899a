"""With the I/O thread, the step thread polls its own selector (listeners, camera results) by wall
time, and every step while a measurement waits for a camera image: an image rendered between
two steps goes out before the next step, however long the polling interval. Real world, real
renderer, real sockets; the step is driven here."""

from __future__ import annotations

import select
import socket

import pytest

import simulator.api.server as server_module
from contracts.robot_api import messages_pb2 as pb
from simulator.api.framing import HEADER, WELCOME
from simulator.api.world_cameras import world_render_worker
from tests.integration.api.harness import RED1, local_server, real_world, wait_until


def _exactly(sock: socket.socket, size: int) -> bytes:
    data = bytearray()
    while len(data) < size:
        chunk = sock.recv(size - len(data))
        if not chunk:
            raise ConnectionError("the server closed the connection")
        data += chunk
    return bytes(data)


def _received_image(sock: socket.socket) -> bool:
    """Read whole frames from ``sock`` until one carries a camera image (False at a timeout)."""
    sock.settimeout(5.0)
    try:
        while True:
            (size,) = HEADER.unpack(_exactly(sock, HEADER.size))
            message = pb.SensorMeasurements.FromString(_exactly(sock, size))
            if message.cameras:
                return True
    except TimeoutError:
        return False


def test_a_rendered_image_goes_out_at_the_next_step(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(server_module, "POLL_INTERVAL_S", 3600.0)  # no poll by time after the first
    world = real_world([RED1])
    cameras = world_render_worker(world)
    server, (port,) = local_server(world, [RED1], cameras=cameras)
    server.start()
    sock = socket.create_connection(("127.0.0.1", port), timeout=5.0)
    try:

        def connected() -> bool:
            server.poll(0.01)
            return server.connection(RED1) is not None

        wait_until(connected)
        assert _exactly(sock, len(WELCOME)) == WELCOME
        conn = server.connection(RED1)
        assert conn is not None
        request = pb.ActuatorRequests()
        request.sensor_time_steps.add(name="Camera", timeStep=32)
        payload = request.SerializeToString()
        sock.sendall(HEADER.pack(len(payload)) + payload)
        wait_until(lambda: conn.stats.messages_in > 0)

        slot = server.slots[RED1]

        def step() -> None:
            server.apply_requests(world.sim_time_ms + world.step_ms)
            world.step()
            world.snapshot()
            server.publish(world.sim_time_ms)

        for _ in range(8):
            step()
            if slot.pending:
                break
        assert slot.pending, "no measurement with a camera image in 8 steps"
        # rendered, not yet collected: the render worker's wake-up is readable
        assert select.select([cameras.wake_fd], [], [], 10.0)[0]
        step()  # its poll before the step collects the image and sends the measurement
        assert not slot.pending
        assert _received_image(sock)
    finally:
        sock.close()
        server.close()
        cameras.close()
