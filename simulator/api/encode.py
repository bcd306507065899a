"""Fast hand encoding of the sensor part of ``SensorMeasurements``.

Building 20+ protobuf sub-messages per robot per step costs more than the physics of that
robot, so the regular sensors are written directly in protobuf wire format: each measurement is a
length-delimited field whose bytes up to the value are fixed per sensor name and cached. The
result is appended to the serialized header (time, real_time, messages, cameras): concatenated
protobuf encodings parse as one message (repeated fields append), so clients see the same
``SensorMeasurements``. Zero values are written explicitly, which parsers accept.
"""

from __future__ import annotations

import struct

_DOUBLE = struct.Struct("<d")
_VEC3 = struct.Struct("<BdBdBd")

ACCELEROMETERS = 4
FORCES = 7
GYROS = 10
POSITION_SENSORS = 11


def _varint(value: int) -> bytes:
    out = bytearray()
    while True:
        byte = value & 0x7F
        value >>= 7
        if value:
            out.append(byte | 0x80)
        else:
            out.append(byte)
            return bytes(out)


def _name_field(name: str) -> bytes:
    raw = name.encode()
    return b"\x0a" + _varint(len(raw)) + raw


class SensorEncoder:
    """Encodes named double and vector measurements; prefixes cached per (field, name)."""

    __slots__ = ("_scalar", "_vector")

    def __init__(self) -> None:
        self._scalar: dict[tuple[int, str], bytes] = {}
        self._vector: dict[tuple[int, str], bytes] = {}

    def scalar(self, field: int, name: str, value: float) -> bytes:
        """``{name, double value = 2}`` as repeated field ``field`` (position, force)."""
        prefix = self._scalar.get((field, name))
        if prefix is None:
            body_len = len(_name_field(name)) + 9
            prefix = _varint(field << 3 | 2) + _varint(body_len) + _name_field(name) + b"\x11"
            self._scalar[(field, name)] = prefix
        return prefix + _DOUBLE.pack(value)

    def vector(self, field: int, name: str, x: float, y: float, z: float) -> bytes:
        """``{name, Vector3 value = 2}`` as repeated field ``field`` (accelerometer, gyro)."""
        prefix = self._vector.get((field, name))
        if prefix is None:
            vec_len = 27
            body_len = len(_name_field(name)) + 2 + vec_len
            prefix = (
                _varint(field << 3 | 2) + _varint(body_len) + _name_field(name)
                + b"\x12" + _varint(vec_len)
            )  # fmt: skip
            self._vector[(field, name)] = prefix
        return prefix + _VEC3.pack(0x09, x, 0x11, y, 0x19, z)
