"""A measurement's cameras written by hand after its header: the bytes protobuf itself writes
for the same message, the image a part of its own (copied once, into the frame). The frame on a
real socket: ``tests/integration/api/test_api_protocol.py``."""

from __future__ import annotations

import os

from contracts.ids import RobotId, TeamColor
from contracts.robot_api import messages_pb2 as pb
from simulator.api import FakeDeviceWorld, RobotSession
from simulator.api.measurement import CameraJob, Measurement

RED1 = RobotId(TeamColor.RED, 1)


def _job(name: str, width: int, height: int, image: bytes | None) -> CameraJob:
    camera = pb.CameraMeasurement(name=name, width=width, height=height, quality=-1)
    return CameraJob(RED1, name, width, height, 96, camera, image)


def _expected(measurement: Measurement, jobs: list[CameraJob], sensors: bytes) -> bytes:
    """What protobuf writes for the same message: header, messages, then every camera with
    its image (field 6 after fields 1 to 3), then the hand-encoded sensors."""
    msg = pb.SensorMeasurements(time=measurement.time, real_time=measurement.real_time)
    msg.messages.extend(measurement.header.messages)
    for job in jobs:
        camera = msg.cameras.add()
        camera.CopyFrom(job.measurement)
        if job.image is not None:
            camera.image = job.image
    return msg.SerializeToString() + sensors


def test_cameras_are_the_bytes_protobuf_writes() -> None:
    sensors = pb.SensorMeasurements(
        gyros=[pb.GyroMeasurement(name="Gyro", value=pb.Vector3(X=0.5, Y=-1.0, Z=2.0))]
    ).SerializeToString()
    images = {
        "full": os.urandom(320 * 240 * 3),  # a league frame: a 3-byte length
        "small": bytes(range(4 * 2 * 3)),  # a 1-byte length
        "black": bytes(0),
        "owed": None,  # not rendered yet: the camera without its image
    }
    for message in (False, True):
        for name, image in images.items():
            measurement = Measurement(96, 1_700_000_000_123, sensors)
            if message:
                measurement.header.messages.add(message_type=pb.Message.WARNING_MESSAGE,
                                                text="too fast")  # fmt: skip
            jobs = [_job("Camera", 320, 240, image), _job("Camera2", 4, 2, images["small"])]
            for job in jobs:
                measurement.add_camera(job)
            assert not measurement.plain
            payload = measurement.payload()
            assert payload == _expected(measurement, jobs, sensors), (name, message)
            parsed = measurement.parsed()
            assert [c.name for c in parsed.cameras] == ["Camera", "Camera2"]
            assert parsed.cameras[0].image == (image or b"")
            assert (parsed.cameras[0].width, parsed.cameras[0].height) == (320, 240)
            assert parsed.cameras[0].quality == -1 and parsed.gyros[0].value.Z == 2.0
            assert len(parsed.messages) == message


def test_session_camera_job_goes_out_with_its_image_in_the_frame() -> None:
    world = FakeDeviceWorld([RED1])
    session = RobotSession(robot=RED1, world=world, rendering_quota_mb_s=87.5,
                           clock_ms=lambda: 42)  # fmt: skip
    request = pb.ActuatorRequests()
    request.sensor_time_steps.add(name="Camera", timeStep=16)
    session.apply(request, step_time_ms=8)
    jobs: list[CameraJob] = []
    measurement = None
    for t in range(8, 64, 8):
        measurement = session.measure(t)
        if measurement.jobs:
            jobs = measurement.jobs
            break
    assert measurement is not None and len(jobs) == 1
    job = jobs[0]
    image = os.urandom(job.width * job.height * 3)
    job.image = image
    parts = measurement.head_parts()
    assert parts[-1] is image  # the image is a part of its own: joined once, into the frame
    parsed = measurement.parsed()
    assert parsed.time == measurement.time and parsed.real_time == 42
    assert len(parsed.cameras) == 1 and parsed.cameras[0].image == image
    assert (parsed.cameras[0].name, parsed.cameras[0].width) == ("Camera", job.width)
    assert measurement.size() == len(measurement.payload())
