"""The remote protocol: the robot API's messages plus a small trainer channel, on one TCP port.

A remote simulator greets like the robot API (``Welcome\\0``, or ``Refused\\0`` when it already
serves a client) and then both sides send frames: a 4-byte big-endian length, then one tag byte
and the payload (the length counts both):

- ``A`` client -> remote: a robot API ``ActuatorRequests`` (the 20 motor position targets);
  the remote steps and answers ``S`` then ``T`` (or ``F``);
- ``S`` remote -> client: a robot API ``SensorMeasurements`` of the learning robot (joint
  positions, accelerometer, gyro, the eight sole forces, the camera image when enabled);
- ``T`` both ways: one JSON object, the trainer channel. Requests ``{"op": ...}``: ``open``
  (``spec``: the session settings), ``reset`` (``request``; answered with ``S`` then ``T``),
  ``place_ball``, ``place_robot``, ``set_game_state``, ``drop_ball`` (``args``), ``health``,
  ``close``. Answers ``{"ok": true, ...}`` (after a step or reset: ``frame``, the ground truth,
  perception and game view of :meth:`envs.frame.Frame.to_wire`) or ``{"ok": false, "error":
  class name, "message": text}``;
- ``F`` remote -> client, in place of ``T`` after a step or reset when the client opened with
  ``"compact": true`` (the remote's ``open`` answer says ``"compact": true`` back) and the frame
  has nothing but ground truth (no perception, game or events): the truth as 14 little-endian
  doubles (:data:`envs.frame.TRUTH_SIZE`), no JSON to write or read at every step.
"""

from __future__ import annotations

import json
import socket
import struct
from typing import Any, TypedDict, cast

import numpy as np
import numpy.typing as npt

from contracts import JSONObject
from contracts.robot_api import messages_pb2 as pb
from envs.frame import N_JOINTS, SENSOR_SIZE, TRUTH_SIZE, FrameWire
from simulator.world import FORCE_SENSORS, MOTOR_NAMES

WELCOME = b"Welcome\0"
REFUSED = b"Refused\0"
HEADER = struct.Struct(">I")
MAX_FRAME_BYTES = 1920 * 1080 * 3 + 100_000
TAG_ACTUATORS = b"A"
TAG_SENSORS = b"S"
TAG_TRAINER = b"T"
TAG_TRUTH = b"F"
_TRUTH = struct.Struct(f"<{TRUTH_SIZE}d")


class ResetWire(TypedDict, total=False):
    """``request`` of a ``reset``: :class:`envs.session_spec.ResetRequest` as JSON."""

    seed: int
    learner_pose: list[float] | None  # x, y, yaw
    ball_xy: list[float] | None


class TrainerMessage(TypedDict, total=False):
    """One ``T`` frame: a request (``op`` and its fields) or an answer (``ok`` and its)."""

    op: str  # open, reset, place_ball, place_robot, set_game_state, drop_ball, health, close
    spec: JSONObject  # open: envs.session_spec.SessionSpec.to_dict()
    compact: bool  # open: F frames wanted (and, answered, granted)
    request: ResetWire  # reset
    args: list[str | int | float]  # the trainer operations' arguments
    ok: bool
    frame: FrameWire  # after a step or reset
    pid: int  # health
    error: str  # the error's class name
    message: str


class WireError(Exception):
    """A broken or closed stream (the caller adds the peer's address)."""


def send_frame(sock: socket.socket, tag: bytes, payload: bytes) -> None:
    sock.sendall(HEADER.pack(len(payload) + 1) + tag + payload)


def send_frames(sock: socket.socket, frames: list[tuple[bytes, bytes]]) -> None:
    sock.sendall(b"".join(HEADER.pack(len(p) + 1) + t + p for t, p in frames))


def send_json(sock: socket.socket, data: TrainerMessage) -> None:
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

    def expect_json(self) -> TrainerMessage:
        return json_object(self.expect(TAG_TRAINER))


def json_object(payload: bytes) -> TrainerMessage:
    """The JSON object of a ``T`` frame (WireError when it is not one)."""
    try:
        data = json.loads(payload)
    except ValueError as exc:
        raise WireError(f"undecodable trainer message: {exc}") from exc
    if not isinstance(data, dict):
        raise WireError("a trainer message must be a JSON object")
    return cast("TrainerMessage", data)  # its fields are read where they are used


# --- robot API messages ---------------------------------------------------------------------
#
# Every step carries one ActuatorRequests (20 named motor positions) and one SensorMeasurements
# (20 named joint positions, accelerometer, gyro, eight named forces, the time). Both are written
# in protobuf's wire format from a fixed layout (field tags, names and lengths are constants;
# only the doubles change), which is several times cheaper than building the messages field by
# field. Decoding takes the same fast path when a message has exactly that layout (what this
# module writes) and parses any other encoding of the same messages with the generated code.


def _varint(value: int) -> bytes:
    out = bytearray()
    while True:
        byte, value = value & 0x7F, value >> 7
        out.append(byte | (0x80 if value else 0))
        if not value:
            return bytes(out)


def _tag(number: int, wire_type: int) -> bytes:
    return _varint(number << 3 | wire_type)


LEN, I64 = 2, 1


def _named_double(field: int, name: str) -> list[bytes]:
    """Constants around one ``{string name = 1; double value = 2;}`` entry of ``field``."""
    raw = name.encode()
    body = _tag(1, LEN) + _varint(len(raw)) + raw + _tag(2, I64)
    return [_tag(field, LEN) + _varint(len(body) + 8) + body]


def _named_vector(field: int, name: str) -> list[bytes]:
    """Constants around one ``{string name = 1; Vector3 value = 2;}`` entry of ``field``."""
    raw = name.encode()
    vector_size = 3 * 9  # X, Y, Z: a tag and eight bytes each
    head = _tag(1, LEN) + _varint(len(raw)) + raw + _tag(2, LEN) + _varint(vector_size)
    size = len(head) + vector_size
    return [_tag(field, LEN) + _varint(size) + head + _tag(1, I64), _tag(2, I64), _tag(3, I64)]


class _Layout:
    """A message as constants alternating with doubles: ``c0 d0 c1 d1 ...``."""

    def __init__(self, constants: list[bytes]) -> None:
        self.constants = tuple(constants)
        self.struct = struct.Struct("<" + "".join(f"{len(c)}sd" for c in constants))
        self._args: list[Any] = [x for c in constants for x in (c, 0.0)]

    def pack(self, values: list[float]) -> bytes:
        args = self._args.copy()
        args[1::2] = values
        return self.struct.pack(*args)

    def unpack(self, payload: bytes) -> tuple[list[float], bytes] | None:
        """The doubles and what follows them, or None when ``payload`` has another layout."""
        if len(payload) < self.struct.size:
            return None
        fields = self.struct.unpack_from(payload)
        if fields[0::2] != self.constants:
            return None
        return list(fields[1::2]), payload[self.struct.size :]


_TARGETS = _Layout([c for name in MOTOR_NAMES for c in _named_double(1, name)])
_SENSORS = _Layout(
    [c for name in MOTOR_NAMES for c in _named_double(11, f"{name}S")]
    + _named_vector(4, "Accelerometer")
    + _named_vector(10, "Gyro")
    + [c for name in FORCE_SENSORS for c in _named_double(7, name)]
)
_TIME_TAG = _tag(1, 0)[0]


def encode_truth(truth: npt.NDArray[np.float64]) -> bytes:
    return _TRUTH.pack(*truth.tolist())


def decode_truth(payload: bytes) -> npt.NDArray[np.float64]:
    if len(payload) != _TRUTH.size:
        raise WireError(f"a truth frame of {len(payload)} bytes (expected {_TRUTH.size})")
    return np.array(_TRUTH.unpack(payload))


def encode_targets(targets: npt.NDArray[np.float64]) -> bytes:
    """An ``ActuatorRequests`` with a position for every motor, in ``MOTOR_NAMES`` order."""
    return _TARGETS.pack(targets.tolist())


def decode_targets(payload: bytes) -> list[float]:
    """Targets in ``MOTOR_NAMES`` order from an ``ActuatorRequests`` (missing motors: NaN,
    which the motors ignore)."""
    fast = _TARGETS.unpack(payload)
    if fast is not None and not fast[1]:
        return fast[0]
    request = pb.ActuatorRequests()
    request.ParseFromString(payload)
    values = {m.name: m.position for m in request.motor_positions}
    return [values.get(name, float("nan")) for name in MOTOR_NAMES]


def encode_sensors(
    time_ms: int, sensors: npt.NDArray[np.float64], image: npt.NDArray[np.uint8] | None
) -> bytes:
    """A ``SensorMeasurements``: joints, accelerometer, gyro, forces, time and the camera."""
    out = _SENSORS.pack(sensors.tolist()) + bytes([_TIME_TAG]) + _varint(time_ms)
    if image is not None:
        h, w = image.shape[:2]
        camera = pb.SensorMeasurements()
        camera.cameras.add(name="Camera", width=w, height=h, quality=-1, image=image.tobytes())
        out += camera.SerializeToString()  # concatenated messages merge (protobuf)
    return out


def _read_varint(data: bytes, at: int) -> tuple[int, int] | None:
    value = shift = 0
    while at < len(data) and shift < 64:
        byte = data[at]
        value |= (byte & 0x7F) << shift
        at += 1
        if not byte & 0x80:
            return value, at
        shift += 7
    return None


def decode_sensors(
    payload: bytes,
) -> tuple[int, npt.NDArray[np.float64], npt.NDArray[np.uint8] | None]:
    fast = _SENSORS.unpack(payload)
    if fast is not None and fast[1][:1] == bytes([_TIME_TAG]):
        values, rest = fast
        read = _read_varint(rest, 1)
        if read is not None:
            time_ms, end = read
            image = None
            if end < len(rest):  # the camera (or anything else): the generated parser
                m = pb.SensorMeasurements()
                m.ParseFromString(rest[end:])
                image = _image(m)
            return time_ms, np.array(values), image
    return _decode_sensors_message(payload)


def _image(m: Any) -> npt.NDArray[np.uint8] | None:
    if not m.cameras:
        return None
    cam = m.cameras[0]
    return np.frombuffer(cam.image, np.uint8).reshape(cam.height, cam.width, 3)


def _decode_sensors_message(
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
    return int(m.time), out, _image(m)
