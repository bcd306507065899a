"""The robot API on the real MuJoCo world: devices, joint control, camera images, HLVS options."""

from __future__ import annotations

import math
import socket
import time

import pytest

from contracts.ids import RobotId, TeamColor
from contracts.match_spec import NetworkSpec
from robot.client import RobotClient
from simulator.api import FakeDeviceWorld
from simulator.api.world_cameras import world_render_worker
from simulator.world import RobotPlacement, World
from tests.integration.api.harness import RED1, running_server, wait_until


def _world() -> World:
    robots = [
        RobotPlacement(id=RED1, model="kid-default", x_m=-1.0, y_m=0.0, yaw_rad=0.0),
        RobotPlacement(
            id=RobotId(TeamColor.BLUE, 1), model="kid-default", x_m=1.0, y_m=0.0, yaw_rad=math.pi
        ),
    ]
    return World.create(field_class="kid", robots=robots, seed=3)


def _client(port: int) -> RobotClient:
    return RobotClient("127.0.0.1", port, retries=3, retry_interval_s=0.1).connect()


def test_real_world_sensors_joint_control_and_camera() -> None:
    world = _world()
    worker = world_render_worker(world)
    robots = (RED1, RobotId(TeamColor.BLUE, 1))
    with running_server(robots=robots, world=world, worker=worker) as (_d, ports):
        with _client(ports[RED1]) as client:
            client.enable_many({"NeckS": 8, "Accelerometer": 8, "Gyro": 8, "llb": 8, "Camera": 32})
            for _ in range(60):
                msg = client.receive(timeout=10)
                client.set_positions({"Neck": 0.6})
            neck = [m for m in (client.receive(timeout=10) for _ in range(40)) if m.cameras]
            last = neck[-1]
            assert last.position_sensors[0].value == pytest.approx(0.6, abs=0.1)
            assert 8.0 < last.accelerometers[0].value.Z < 11.5  # gravity, standing
            assert last.forces and last.gyros
            image = last.cameras[0]
            assert (image.width, image.height, image.quality) == (320, 240, -1)
            assert len(image.image) == 320 * 240 * 3
            assert len(set(image.image[::997])) > 3  # a picture, not a uniform buffer
            assert msg.time > 0
    assert worker.frames >= 2


def test_host_names_are_accepted_by_reverse_lookup() -> None:
    with running_server(hosts=("localhost",)) as (driver, ports), _client(ports[RED1]) as c:
        assert c.receive(timeout=10).time > 0
        assert driver.server.connected() == ["red-1"]


def test_blocking_send_restores_the_hlvs_stall() -> None:
    network = NetworkSpec(api_bind_host="127.0.0.1", blocking_send=True)
    fake = FakeDeviceWorld((RED1, RobotId(TeamColor.BLUE, 1)))  # thousands of steps per second
    robots = fake.robot_ids
    with running_server(robots=robots, network=network, pause_s=0.0, world=fake) as (driver, ports):
        raw = socket.socket()
        raw.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 4096)
        raw.connect(("127.0.0.1", ports[RED1]))
        assert raw.recv(8) == b"Welcome\0"

        def stalled() -> bool:
            before = driver.steps
            time.sleep(0.3)
            return driver.steps == before

        wait_until(stalled, 30)  # the step loop waits for the reader, as in HLVS
        raw.recv(1 << 20)
        steps = driver.steps
        wait_until(lambda: driver.steps > steps)  # reading lets it go on
        raw.close()
        wait_until(lambda: driver.steps > steps + 100)
