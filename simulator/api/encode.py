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
from collections.abc import Sequence

import numpy as np

_DOUBLE = struct.Struct("<d")
_VEC3 = struct.Struct("<BdBdBd")

ACCELEROMETERS = 4
FORCES = 7
GYROS = 10
POSITION_SENSORS = 11


def varint(value: int) -> bytes:
    """Protobuf base-128 varint of a non-negative integer."""
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
    return b"\x0a" + varint(len(raw)) + raw


def scalar_prefix(field: int, name: str) -> bytes:
    """Wire bytes of ``{name, double value = 2}`` up to the 8 value bytes."""
    body_len = len(_name_field(name)) + 9
    return varint(field << 3 | 2) + varint(body_len) + _name_field(name) + b"\x11"


def vector_prefix(field: int, name: str) -> bytes:
    """Wire bytes of ``{name, Vector3 value = 2}`` up to the Vector3's first tag."""
    vec_len = 27
    body_len = len(_name_field(name)) + 2 + vec_len
    return varint(field << 3 | 2) + varint(body_len) + _name_field(name) + b"\x12" + varint(vec_len)


class SensorLayout:
    """The wire bytes of a fixed list of sensors with the values left open.

    ``entries`` are ``(field, name, width)`` with width 1 (a double) or 3 (a Vector3);
    :meth:`encode` fills the values (flat, in entry order) with one numpy scatter, so a
    measurement of 22 sensors costs about as much as one of them.
    """

    __slots__ = ("template", "byte_index", "values")

    def __init__(self, entries: Sequence[tuple[int, str, int]]) -> None:
        template = bytearray()
        starts: list[int] = []
        for field, name, width in entries:
            if width == 1:
                template += scalar_prefix(field, name)
                starts.append(len(template))
                template += bytes(8)
            elif width == 3:
                template += vector_prefix(field, name)
                for tag in (0x09, 0x11, 0x19):
                    template.append(tag)
                    starts.append(len(template))
                    template += bytes(8)
            else:
                raise ValueError(f"sensor {name!r}: width {width}, expected 1 or 3")
        self.values = len(starts)
        self.template = np.frombuffer(bytes(template), dtype=np.uint8)
        self.byte_index = (np.asarray(starts, dtype=np.int64)[:, None] + np.arange(8)).ravel()

    def encode(self, values: Sequence[float] | np.ndarray) -> bytes:
        out = self.template.copy()
        out[self.byte_index] = np.ascontiguousarray(values, dtype="<f8").view(np.uint8)
        return out.tobytes()


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
            prefix = self._scalar[(field, name)] = scalar_prefix(field, name)
        return prefix + _DOUBLE.pack(value)

    def vector(self, field: int, name: str, x: float, y: float, z: float) -> bytes:
        """``{name, Vector3 value = 2}`` as repeated field ``field`` (accelerometer, gyro)."""
        prefix = self._vector.get((field, name))
        if prefix is None:
            prefix = self._vector[(field, name)] = vector_prefix(field, name)
        return prefix + _VEC3.pack(0x09, x, 0x11, y, 0x19, z)
