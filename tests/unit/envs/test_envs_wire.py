"""The remote protocol's frames and robot API messages, over a real socket pair."""

from __future__ import annotations

import math
import socket
import struct

import numpy as np
import pytest

from envs.frame import SENSOR_SIZE
from envs.wire import (
    TAG_TRAINER,
    FrameReader,
    WireError,
    decode_sensors,
    decode_targets,
    encode_sensors,
    encode_targets,
    send_frame,
    send_json,
)


def test_sensors_and_targets_round_trip() -> None:
    sensors = np.linspace(-1.0, 1.0, SENSOR_SIZE)
    image = np.arange(4 * 6 * 3, dtype=np.uint8).reshape(4, 6, 3)
    time_ms, decoded, got_image = decode_sensors(encode_sensors(48, sensors, image))
    assert time_ms == 48 and np.allclose(decoded, sensors)
    assert got_image is not None and np.array_equal(got_image, image)
    targets = np.linspace(-0.5, 0.5, 20)
    assert np.allclose(decode_targets(encode_targets(targets)), targets)


def test_missing_motor_targets_are_nan_and_ignored_by_the_motors() -> None:
    from contracts.robot_api import messages_pb2 as pb

    request = pb.ActuatorRequests()
    request.motor_positions.add(name="Neck", position=0.3)
    values = decode_targets(request.SerializeToString())
    assert values[0] == pytest.approx(0.3) and all(math.isnan(v) for v in values[1:])


def test_frames_and_broken_streams() -> None:
    a, b = socket.socketpair()
    with a, b:
        send_json(a, {"op": "health"})
        send_frame(a, b"S", b"xyz")
        reader = FrameReader(b)
        assert reader.expect_json() == {"op": "health"}
        with pytest.raises(WireError, match="expected a 'T' frame"):
            reader.expect(TAG_TRAINER)
        a.sendall(struct.pack(">I", 0))
        with pytest.raises(WireError, match="bad frame length 0"):
            reader.read()
        a.close()
        with pytest.raises(WireError, match="closed"):
            FrameReader(b).read()


def test_the_fixed_layout_is_the_robot_api_message() -> None:
    """What the fast encoders write is the robot API's protobuf message (the generated parser
    reads every name and value back), and the fast decoders agree with the generated parser on
    any encoding of the same message."""
    from contracts.robot_api import messages_pb2 as pb
    from envs.frame import N_JOINTS
    from envs.wire import _decode_sensors_message
    from simulator.world import FORCE_SENSORS, MOTOR_NAMES

    rng = np.random.default_rng(4)
    targets = rng.normal(size=20)
    targets[3] = 0.0  # protobuf would leave a zero out; the layout keeps it
    targets[5] = float("nan")
    request = pb.ActuatorRequests()
    request.ParseFromString(encode_targets(targets))
    assert [m.name for m in request.motor_positions] == list(MOTOR_NAMES)
    got = [m.position for m in request.motor_positions]
    assert np.array_equal(got, targets, equal_nan=True)
    assert np.array_equal(decode_targets(request.SerializeToString()), targets, equal_nan=True)

    sensors = rng.normal(size=SENSOR_SIZE)
    for time_ms, image in [(0, None), (8, None), (2**31 + 5, None),
                           (96, rng.integers(0, 255, (3, 5, 3), dtype=np.uint8))]:  # fmt: skip
        payload = encode_sensors(time_ms, sensors, image)
        m = pb.SensorMeasurements()
        m.ParseFromString(payload)
        assert m.time == time_ms
        assert [p.name for p in m.position_sensors] == [f"{n}S" for n in MOTOR_NAMES]
        assert [p.value for p in m.position_sensors] == sensors[:N_JOINTS].tolist()
        a, g = m.accelerometers[0], m.gyros[0]
        assert (a.name, g.name) == ("Accelerometer", "Gyro")
        assert [a.value.X, a.value.Y, a.value.Z, g.value.X, g.value.Y, g.value.Z] == (
            sensors[N_JOINTS : N_JOINTS + 6].tolist())  # fmt: skip
        assert [f.name for f in m.forces] == list(FORCE_SENSORS)
        assert [f.value for f in m.forces] == sensors[N_JOINTS + 6 :].tolist()
        fast = decode_sensors(payload)
        for other in (payload, m.SerializeToString()):  # ours and the generated encoding
            generic = _decode_sensors_message(other)
            assert fast[0] == generic[0] and np.array_equal(fast[1], generic[1])
            assert (fast[2] is None) == (image is None) == (generic[2] is None)
            if image is not None:
                assert np.array_equal(fast[2], image) and np.array_equal(generic[2], image)
        assert np.array_equal(decode_sensors(m.SerializeToString())[1], sensors)


def test_truth_frames() -> None:
    from envs.frame import TRUTH_SIZE
    from envs.wire import decode_truth, encode_truth

    truth = np.linspace(-3.0, 3.0, TRUTH_SIZE)
    assert np.array_equal(decode_truth(encode_truth(truth)), truth)
    with pytest.raises(WireError, match="a truth frame of 8 bytes"):
        decode_truth(b"\0" * 8)
