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
