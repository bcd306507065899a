"""The messages keep HLVS's field numbers: wire bytes pinned by hand-computed expectations."""

from __future__ import annotations

import struct

import pytest

from contracts.robot_api import messages_pb2 as pb
from simulator.api import FrameDecoder, FramingError, encode_frame
from simulator.api.framing import MAX_FRAME_BYTES


def test_actuator_requests_bytes() -> None:
    request = pb.ActuatorRequests()
    request.motor_positions.add(name="Neck", position=1.5)
    request.sensor_time_steps.add(name="NeckS", timeStep=8)
    request.motor_pids.add(name="Head").PID.CopyFrom(pb.Vector3(X=1.0))
    position = b"\x0a\x04Neck" + b"\x11" + struct.pack("<d", 1.5)
    time_step = b"\x0a\x05NeckS" + b"\x10\x08"
    pid = b"\x0a\x04Head" + b"\x12\x09" + b"\x09" + struct.pack("<d", 1.0)
    expected = (
        b"\x0a" + bytes([len(position)]) + position
        + b"\x2a" + bytes([len(pid)]) + pid
        + b"\x32" + bytes([len(time_step)]) + time_step
    )  # fmt: skip
    assert request.SerializeToString() == expected


def test_sensor_measurements_bytes() -> None:
    msg = pb.SensorMeasurements(time=8, real_time=1000)
    msg.messages.add(message_type=pb.Message.WARNING_MESSAGE, text="x")
    msg.gyros.add(name="Gyro").value.CopyFrom(pb.Vector3(Z=2.0))
    msg.cameras.add(name="C", width=2, height=1, quality=-1, image=b"abcdef")
    msg.position_sensors.add(name="NeckS", value=0.5)
    gyro = b"\x0a\x04Gyro" + b"\x12\x09" + b"\x19" + struct.pack("<d", 2.0)
    camera = b"\x0a\x01C" + b"\x10\x02" + b"\x18\x01" + b"\x20\x01" + b"\x2a\x06abcdef"
    position = b"\x0a\x05NeckS" + b"\x11" + struct.pack("<d", 0.5)
    expected = (
        b"\x08\x08" + b"\x10\xe8\x07"
        + b"\x1a\x05\x08\x01\x12\x01x"
        + b"\x32" + bytes([len(camera)]) + camera
        + b"\x52" + bytes([len(gyro)]) + gyro
        + b"\x5a" + bytes([len(position)]) + position
    )  # fmt: skip
    assert msg.SerializeToString() == expected


def test_field_names_are_hlvs_names() -> None:
    assert pb.SensorTimeStep.DESCRIPTOR.fields_by_name["timeStep"].number == 2
    assert [f.name for f in pb.Vector3.DESCRIPTOR.fields] == ["X", "Y", "Z"]
    numbers = {f.name: f.number for f in pb.ActuatorRequests.DESCRIPTOR.fields}
    assert numbers == {
        "motor_positions": 1, "motor_velocities": 2, "motor_forces": 3, "motor_torques": 4,
        "motor_pids": 5, "sensor_time_steps": 6, "camera_qualities": 7, "camera_exposures": 8,
    }  # fmt: skip
    assert pb.ActuatorRequests.DESCRIPTOR.file.package == ""


def test_frames_split_anywhere_are_reassembled() -> None:
    payloads = [b"a", b"bc" * 100, b"\x00" * 7]
    stream = b"".join(encode_frame(p) for p in payloads)
    assert stream[:4] == b"\x00\x00\x00\x01"
    for cut in range(len(stream)):
        decoder = FrameDecoder()
        got = decoder.feed(stream[:cut]) + decoder.feed(stream[cut:])
        assert got == payloads
        assert decoder.buffered == 0


def test_an_empty_frame_is_yielded_empty_between_others() -> None:
    """League ``controllers/player/player.cpp``: a 0-length message (an empty
    ``ActuatorRequests``) is skipped, the stream stays in sync."""
    stream = encode_frame(b"a") + struct.pack(">I", 0) + encode_frame(b"bc")
    for cut in range(len(stream)):
        decoder = FrameDecoder()
        assert decoder.feed(stream[:cut]) + decoder.feed(stream[cut:]) == [b"a", b"", b"bc"]
    assert FrameDecoder().feed(struct.pack(">I", 0)) == [b""]


@pytest.mark.parametrize("length", [MAX_FRAME_BYTES + 1, 0xFFFFFFFF])
def test_out_of_range_length_is_a_framing_error(length: int) -> None:
    with pytest.raises(FramingError) as info:
        FrameDecoder().feed(struct.pack(">I", length) + b"xx")
    assert info.value.length == length
    assert info.value.limit == MAX_FRAME_BYTES


def test_hand_encoded_sensors_parse_like_protobuf() -> None:
    from simulator.api.encode import ACCELEROMETERS, GYROS, POSITION_SENSORS, SensorEncoder

    encoder = SensorEncoder()
    header = pb.SensorMeasurements(time=16, real_time=5)
    header.messages.add(message_type=pb.Message.WARNING_MESSAGE, text="w")
    sensors = (
        encoder.vector(ACCELEROMETERS, "Accelerometer", 0.1, -0.2, 9.81)
        + encoder.vector(GYROS, "Gyro", 0.0, 0.0, 0.0)
        + encoder.scalar(POSITION_SENSORS, "NeckS", 0.25)
        + encoder.scalar(POSITION_SENSORS, "HeadS", -1.5)
    )
    assert encoder.scalar(POSITION_SENSORS, "NeckS", 0.5) == (
        b"\x5a\x10\x0a\x05NeckS\x11" + struct.pack("<d", 0.5)
    )
    parsed = pb.SensorMeasurements()
    parsed.ParseFromString(header.SerializeToString() + sensors)
    expected = pb.SensorMeasurements(time=16, real_time=5)
    expected.messages.add(message_type=pb.Message.WARNING_MESSAGE, text="w")
    expected.accelerometers.add(name="Accelerometer").value.CopyFrom(
        pb.Vector3(X=0.1, Y=-0.2, Z=9.81)
    )
    expected.gyros.add(name="Gyro").value.CopyFrom(pb.Vector3())
    expected.position_sensors.add(name="NeckS", value=0.25)
    expected.position_sensors.add(name="HeadS", value=-1.5)
    assert parsed == expected
