"""The remote protocol: the robot API's messages plus a small trainer channel, on one TCP port.

A remote simulator greets like the robot API (``Welcome\\0``, or ``Refused\\0`` when it already
serves a client) and then both sides send frames: a 4-byte big-endian length, then one tag byte
and the payload (the length counts both):

- ``A`` client -> remote: a robot API ``ActuatorRequests`` (the 20 motor position targets);
  the remote steps and answers ``S`` then ``T``;
- ``S`` remote -> client: a robot API ``SensorMeasurements`` of the learning robot (joint
  positions, accelerometer, gyro, the eight sole forces, the camera image when enabled);
- ``T`` both ways: one JSON object, the trainer channel. Requests ``{"op": ...}``: ``open``
  (``spec``: the session settings), ``reset`` (``request``; answered with ``S`` then ``T``),
  ``place_ball``, ``place_robot``, ``set_game_state``, ``drop_ball`` (``args``), ``health``,
  ``close``. Answers ``{"ok": true, ...}`` (after a step or reset: ``frame``, the ground truth,
  perception and game view of :meth:`envs.frame.Frame.to_wire`) or ``{"ok": false, "error":
  class name, "message": text}``.
"""

from __future__ import annotations

import json
import socket
import struct
from typing import Any

import numpy as np
import numpy.typing as npt

from contracts.robot_api import messages_pb2 as pb
from envs.frame import N_JOINTS, SENSOR_SIZE
from simulator.world import FORCE_SENSORS, MOTOR_NAMES

WELCOME = b"Welcome\0"
REFUSED = b"Refused\0"
HEADER = struct.Struct(">I")
MAX_FRAME_BYTES = 1920 * 1080 * 3 + 100_000
TAG_ACTUATORS = b"A"
TAG_SENSORS = b"S"
TAG_TRAINER = b"T"


class WireError(Exception):
    """A broken or closed stream (the caller adds the peer's address)."""


def send_frame(sock: socket.socket, tag: bytes, payload: bytes) -> None:
    sock.sendall(HEADER.pack(len(payload) + 1) + tag + payload)


def send_frames(sock: socket.socket, frames: list[tuple[bytes, bytes]]) -> None:
    sock.sendall(b"".join(HEADER.pack(len(p) + 1) + t + p for t, p in frames))


def send_json(sock: socket.socket, data: dict[str, Any]) -> None:
    send_frame(sock, TAG_TRAINER, json.dumps(data).encode())


class FrameReader:
    """Reads tagged frames from a blocking socket."""

    def __init__(self, sock: socket.socket) -> None:
        self.sock = sock
        self._buffer = bytearray()

    def _fill(self, size: int) -> None:
        while len(self._buffer) < size:
            chunk = self.sock.recv(max(65536, size - len(self._buffer)))
            if not chunk:
                raise WireError("connection closed by the peer")
            self._buffer += chunk

    def read(self) -> tuple[bytes, bytes]:
        self._fill(4)
        (length,) = HEADER.unpack_from(self._buffer)
        if length < 1 or length > MAX_FRAME_BYTES:
            raise WireError(f"bad frame length {length}")
        self._fill(4 + length)
        tag = bytes(self._buffer[4:5])
        payload = bytes(self._buffer[5 : 4 + length])
        del self._buffer[: 4 + length]
        return tag, payload

    def expect(self, tag: bytes) -> bytes:
        got, payload = self.read()
        if got != tag:
            raise WireError(f"expected a {tag.decode()!r} frame, got {got!r}")
        return payload

    def expect_json(self) -> dict[str, Any]:
        payload = self.expect(TAG_TRAINER)
        try:
            data = json.loads(payload)
        except ValueError as exc:
            raise WireError(f"undecodable trainer message: {exc}") from exc
        if not isinstance(data, dict):
            raise WireError("a trainer message must be a JSON object")
        return data


def encode_targets(targets: npt.NDArray[np.float64]) -> bytes:
    request = pb.ActuatorRequests()
    for name, value in zip(MOTOR_NAMES, targets.tolist(), strict=True):
        request.motor_positions.add(name=name, position=value)
    return bytes(request.SerializeToString())


def decode_targets(payload: bytes) -> list[float]:
    """Targets in ``MOTOR_NAMES`` order from an ``ActuatorRequests`` (missing motors: NaN,
    which the motors ignore)."""
    request = pb.ActuatorRequests()
    request.ParseFromString(payload)
    values = {m.name: m.position for m in request.motor_positions}
    return [values.get(name, float("nan")) for name in MOTOR_NAMES]


def encode_sensors(
    time_ms: int, sensors: npt.NDArray[np.float64], image: npt.NDArray[np.uint8] | None
) -> bytes:
    m = pb.SensorMeasurements(time=time_ms)
    values = sensors.tolist()
    for name, value in zip(MOTOR_NAMES, values[:N_JOINTS], strict=True):
        m.position_sensors.add(name=f"{name}S", value=value)
    ax, ay, az, gx, gy, gz = values[N_JOINTS : N_JOINTS + 6]
    m.accelerometers.add(name="Accelerometer", value=pb.Vector3(X=ax, Y=ay, Z=az))
    m.gyros.add(name="Gyro", value=pb.Vector3(X=gx, Y=gy, Z=gz))
    for name, value in zip(FORCE_SENSORS, values[N_JOINTS + 6 :], strict=True):
        m.forces.add(name=name, value=value)
    if image is not None:
        h, w = image.shape[:2]
        m.cameras.add(name="Camera", width=w, height=h, quality=-1, image=image.tobytes())
    return bytes(m.SerializeToString())


def decode_sensors(
    payload: bytes,
) -> tuple[int, npt.NDArray[np.float64], npt.NDArray[np.uint8] | None]:
    m = pb.SensorMeasurements()
    m.ParseFromString(payload)
    out = np.zeros(SENSOR_SIZE)
    joints = {p.name: p.value for p in m.position_sensors}
    out[:N_JOINTS] = [joints.get(f"{n}S", 0.0) for n in MOTOR_NAMES]
    if m.accelerometers:
        v = m.accelerometers[0].value
        out[N_JOINTS : N_JOINTS + 3] = (v.X, v.Y, v.Z)
    if m.gyros:
        v = m.gyros[0].value
        out[N_JOINTS + 3 : N_JOINTS + 6] = (v.X, v.Y, v.Z)
    forces = {f.name: f.value for f in m.forces}
    out[N_JOINTS + 6 :] = [forces.get(n, 0.0) for n in FORCE_SENSORS]
    image = None
    if m.cameras:
        cam = m.cameras[0]
        image = np.frombuffer(cam.image, np.uint8).reshape(cam.height, cam.width, 3)
    return int(m.time), out, image
