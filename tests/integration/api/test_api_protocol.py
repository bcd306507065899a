"""Robot API conformance over real sockets on 127.0.0.1 (fake world, real server)."""

from __future__ import annotations

import socket
import struct
import time

import pytest

from contracts.match_spec import NetworkSpec
from contracts.robot_api import messages_pb2 as pb
from robot.client import HandshakeRefused, RobotClient
from simulator.api import FakeDeviceWorld
from tests.integration.api.harness import BLUE1, RED1, RED2, running_server, wait_until


def _client(port: int) -> RobotClient:
    return RobotClient("127.0.0.1", port, retries=3, retry_interval_s=0.1).connect()


def _texts(msg: pb.SensorMeasurements) -> list[str]:
    return [m.text for m in msg.messages]


def _next_with(client: RobotClient, predicate, limit: int = 400) -> pb.SensorMeasurements:  # type: ignore[no-untyped-def]
    for _ in range(limit):
        msg = client.receive(timeout=5)
        if predicate(msg):
            return msg
    raise AssertionError("no matching measurement")


def test_welcome_then_one_measurement_per_step() -> None:
    with running_server() as (driver, ports), _client(ports[RED1]) as client:
        first = client.receive(timeout=5)
        second = client.receive(timeout=5)
        assert first.time % 8 == 0 and first.time > 0
        assert second.time == first.time + 8
        assert abs(second.real_time - time.time() * 1000) < 5000
        assert not second.position_sensors  # everything starts disabled
        assert driver.server.connected() == ["red-1"]


def test_refused_peer_not_in_hosts() -> None:
    with running_server(hosts=("10.9.9.9",)) as (driver, ports):
        with pytest.raises(HandshakeRefused):
            _client(ports[RED1])
        assert driver.server.statistics()["red-1"]["refused_connections"] == 1


def test_second_client_on_same_port_is_refused_first_keeps_serving() -> None:
    with running_server() as (driver, ports), _client(ports[RED1]) as first:
        raw = socket.create_connection(("127.0.0.1", ports[RED1]), timeout=5)
        assert raw.recv(8) == b"Refused\0"
        assert raw.recv(8) == b""  # closed by the server
        raw.close()
        t0 = first.receive(timeout=5).time
        assert first.receive(timeout=5).time == t0 + 8
        assert driver.server.statistics()["red-1"]["refused_connections"] == 1


def test_sensor_periods_follow_hlvs_timing() -> None:
    with running_server() as (_driver, ports), _client(ports[RED1]) as client:
        client.enable_many({"NeckS": 8, "Accelerometer": 16, "Gyro": 24})
        neck = _next_with(client, lambda m: bool(m.position_sensors))
        t_enable = neck.time - 8  # first report one period after enabling
        seen: dict[str, list[int]] = {"acc": [], "gyro": [], "neck": [neck.time]}
        for _ in range(12):
            msg = client.receive(timeout=5)
            if msg.accelerometers:
                seen["acc"].append(msg.time)
            if msg.gyros:
                seen["gyro"].append(msg.time)
            if msg.position_sensors:
                seen["neck"].append(msg.time)
                assert msg.position_sensors[0].name == "NeckS"
        assert all((t - t_enable) % 16 == 0 for t in seen["acc"]) and seen["acc"]
        assert all((t - t_enable) % 24 == 0 for t in seen["gyro"]) and seen["gyro"]
        assert seen["neck"] == list(range(neck.time, neck.time + 13 * 8, 8))
        assert msg.accelerometers or msg.gyros or True
        client.enable("NeckS", 0)
        _next_with(client, lambda m: not m.position_sensors and m.time > msg.time)


def test_warnings_use_hlvs_texts() -> None:
    with running_server() as (_driver, ports), _client(ports[RED1]) as client:
        request = pb.ActuatorRequests()
        request.motor_positions.add(name="Tail", position=1.0)
        request.motor_velocities.add(name="Tail", velocity=1.0)
        request.motor_torques.add(name="Tail", torque=1.0)
        request.motor_pids.add(name="Tail")
        request.camera_qualities.add(name="Camera", quality=50)
        request.sensor_time_steps.add(name="NeckS", timeStep=4)
        request.sensor_time_steps.add(name="Gyro", timeStep=12)
        request.sensor_time_steps.add(name="Camera", timeStep=8)
        request.sensor_time_steps.add(name="Lidar", timeStep=8)
        client.send(request)
        msg = _next_with(client, lambda m: bool(m.messages))
        assert all(m.message_type == pb.Message.WARNING_MESSAGE for m in msg.messages)
        assert _texts(msg) == [
            'Motor "Tail" not found, position command ignored.',
            'Motor "Tail" not found, velocity command ignored.',
            'Motor "Tail" not found, torque command ignored.',
            'Motor "Tail" not found, PID command ignored.',
            "CameraQuality is not yet implemented, ignored.",
            'Time step for "NeckS" should be greater or equal to 8, ignoring 4 value.',
            'Time step for "Gyro" should be a multiple of 8, ignoring 12 value.',
            'Time step for "Camera" should be greater or equal to 16, ignoring 8 value.',
            'Device "Lidar" not found, time step command, ignored.',
        ]
        assert not client.receive(timeout=5).messages  # one request, its warnings once


def test_positions_reach_the_world_and_later_requests_override() -> None:
    world = FakeDeviceWorld((RED1, RED2, BLUE1))
    with running_server(world=world) as (driver, ports), _client(ports[RED1]) as client:
        client.set_positions({"Neck": 0.3, "Head": 0.1})
        client.set_positions({"Neck": 0.7})
        client.enable("NeckS", 8)
        msg = _next_with(client, lambda m: bool(m.position_sensors))
        assert msg.position_sensors[0].value == pytest.approx(0.7)
        assert driver.world.targets[RED1]["Head"] == pytest.approx(0.1)


def test_network_quota_replaces_the_message_keeping_times() -> None:
    network = NetworkSpec(api_bind_host="127.0.0.1", team_quota_mb_s=0.001)
    with running_server(network=network, team_size=4) as (driver, ports):
        with _client(ports[RED1]) as client:
            client.enable_many({f"{m}S": 8 for m in ("Neck", "Head", "PelvL", "PelvR")})
            msg = _next_with(client, lambda m: m.messages and m.messages[0].message_type == 0)
            assert _texts(msg) == [f"{0.001 / 4:f} MB/s quota exceeded."]
            assert msg.time > 0 and msg.real_time > 0 and not msg.position_sensors
        assert driver.server.statistics()["red-1"]["quota_errors"] >= 1


def test_rendering_quota_refuses_camera_with_hlvs_warning() -> None:
    network = NetworkSpec(api_bind_host="127.0.0.1", rendering_quota_mb_s=20.0)
    with running_server(network=network, team_size=2, cameras=True) as (_d, ports):
        with _client(ports[RED1]) as client:
            client.enable("Camera", 16)  # 320x240x3 @ 16 ms = 13.7 MB/s > 10 MB/s
            msg = _next_with(client, lambda m: bool(m.messages))
            assert _texts(msg) == [
                "requested rendering bandwidth is above the limit (14MB/s > 10MB/s)"
            ]
            client.enable("Camera", 32)  # 6.9 MB/s fits
            image = _next_with(client, lambda m: bool(m.cameras)).cameras[0]
            assert (image.width, image.height, image.quality) == (320, 240, -1)
            assert image.image[:3] == bytes((1, 0, 255))  # B, G, R of the fake red-1 image
            assert len(image.image) == 320 * 240 * 3


def test_camera_period_and_robots_without_camera_keep_their_pace() -> None:
    with running_server(cameras=True) as (_d, ports):
        with _client(ports[RED1]) as cam, _client(ports[BLUE1]) as plain:
            cam.enable("Camera", 32)
            times = [m.time for m in (cam.receive(timeout=5) for _ in range(20)) if m.cameras]
            assert len(times) >= 4
            assert {b - a for a, b in zip(times, times[1:], strict=False)} == {32}
            t0 = plain.receive(timeout=5).time
            assert [plain.receive(timeout=5).time for _ in range(3)] == [t0 + 8, t0 + 16, t0 + 24]


@pytest.mark.parametrize(
    "garbage",
    [
        struct.pack(">I", 1920 * 1080 * 3 + 1001) + b"x",  # over the limit
        struct.pack(">I", 3) + b"\xff\xff\xff",  # not an ActuatorRequests
        b"GET / HTTP/1.1\r\n\r\n",  # garbage: an absurd length
    ],
)
def test_bad_input_closes_only_that_client(garbage: bytes) -> None:
    """(An empty frame is no bad input: the league's player skips it, and so do we; see
    tests/unit/api/test_api_empty_frame.py.)"""
    with running_server() as (driver, ports), _client(ports[RED2]) as other:
        raw = socket.create_connection(("127.0.0.1", ports[RED1]), timeout=5)
        assert raw.recv(8) == b"Welcome\0"
        raw.sendall(garbage)
        wait_until(lambda: driver.server.statistics()["red-1"]["disconnects"])
        raw.close()
        t0 = other.receive(timeout=5).time
        assert other.receive(timeout=5).time == t0 + 8
        stats = driver.server.statistics()["red-1"]
        assert stats["bad_frames"] + stats["decode_errors"] == 1
        with _client(ports[RED1]) as again:  # the port accepts a new client
            assert again.receive(timeout=5).time > 0


def test_half_frame_then_disconnect_and_reconnect_keeps_sensors() -> None:
    with running_server() as (driver, ports):
        with _client(ports[RED1]) as client:
            client.enable("NeckS", 8)
            _next_with(client, lambda m: bool(m.position_sensors))
            client._socket().sendall(struct.pack(">I", 100) + b"half")
        wait_until(lambda: not driver.server.connected())
        assert len(driver.server.statistics()["red-1"]["disconnect_reasons"]) == 1
        with _client(ports[RED1]) as again:
            assert _next_with(again, lambda m: bool(m.position_sensors), limit=3)


def test_limp_robot_caches_commands_and_removed_robot_gets_time_only() -> None:
    fake = FakeDeviceWorld((RED1, RED2, BLUE1))
    with running_server(world=fake) as (driver, ports), _client(ports[RED1]) as client:
        world = driver.world
        client.enable("NeckS", 8)
        _next_with(client, lambda m: bool(m.position_sensors))
        world.limp.add(RED1)
        received = driver.server.statistics()["red-1"]["messages_in"]
        client.set_positions({"Neck": 1.2})
        wait_until(lambda: driver.server.statistics()["red-1"]["messages_in"] > received)
        t_sent = world.sim_time_ms  # applied (ignored) at the next step
        msg = _next_with(client, lambda m: m.time > t_sent + 24)
        assert msg.position_sensors  # sensors still sent while limp
        assert ("position", RED1, "Neck", (1.2,)) not in world.calls
        world.limp.discard(RED1)
        wait_until(lambda: ("position", RED1, "Neck", (1.2,)) in world.calls)
        world.removed.add(RED1)
        t_removed = world.sim_time_ms  # measurements already queued may predate the removal
        msg = _next_with(client, lambda m: m.time > t_removed + 16)
        assert msg.time > 0 and msg.real_time > 0
        assert not msg.position_sensors and not msg.messages
