"""Decoding of the usual ``ActuatorRequests`` without protobuf: position targets only.

A robot controller sends the same motor names in the same order every step; only the 8-byte
doubles change. The first such request is decoded by protobuf and scanned once
(:func:`scan_positions`) into a :class:`PositionTemplate`: the fixed wire bytes between the
values and one ``struct`` format for the whole frame. A later frame of the same length whose
fixed bytes are identical has the same structure (each item ``{name = 1, position = 2}``), so
its targets are the unpacked doubles (:meth:`PositionTemplate.match`). Anything else (other
fields, a target of exactly 0.0 that a proto3 encoder leaves out, another name list) goes the
protobuf way, so both ways give the same result.
"""

from __future__ import annotations

import math
import struct
from collections.abc import Sequence

import numpy as np
import numpy.typing as npt

TargetValues = Sequence[float] | npt.NDArray[np.float64]


class PositionTargets:
    """Position targets of one request: ``names[i]`` to ``values[i]`` (in request order).
    Read from a frame, ``values`` is a float64 array and ``finite`` tells that none is a NaN
    or an infinity (both made on the I/O thread, so that the step thread writes every robot's
    targets with one concatenation and no check); else ``finite`` is False (checked there)."""

    __slots__ = ("names", "values", "finite")

    def __init__(
        self, names: tuple[str, ...], values: TargetValues, finite: bool = False
    ) -> None:
        self.names = names
        self.values = values
        self.finite = finite


class Notice:
    """A warning the reader owes the client, queued with its requests so that it reaches the
    client's session in order (a request dropped before decoding: :mod:`simulator.api.bounds`);
    the session sends ``text`` in its next measurement."""

    __slots__ = ("text",)

    def __init__(self, text: str) -> None:
        self.text = text


class PositionTemplate:
    """The wire layout of one request made of ``motor_positions`` only."""

    __slots__ = ("names", "size", "fixed", "_unpack")

    def __init__(self, names: tuple[str, ...], fixed: tuple[bytes, ...]) -> None:
        self.names = names
        self.fixed = fixed  # the wire bytes before each target, in order
        layout = struct.Struct("<" + "".join(f"{len(segment)}sd" for segment in fixed))
        self._unpack = layout.unpack
        self.size = layout.size

    def _values(self, frame: bytes) -> tuple[float, ...] | None:
        """The targets of ``frame`` when it has this layout, else None."""
        if len(frame) != self.size:
            return None
        parts = self._unpack(frame)
        if parts[0::2] != self.fixed:
            return None
        values: tuple[float, ...] = parts[1::2]
        return values

    def finite_values(self, frame: bytes) -> tuple[float, ...] | None:
        """The targets of ``frame`` when it has this layout and all of them are finite, else
        None: :meth:`match` without the objects, for a target board's span."""
        values = self._values(frame)
        return values if values is not None and math.isfinite(sum(values)) else None

    def match(self, frame: bytes) -> PositionTargets | None:
        """The targets of ``frame`` when it has this layout, else None."""
        values = self._values(frame)
        if values is None:
            return None
        # a sum that is finite has no NaN nor infinity (a huge one that overflows: checked later)
        finite = math.isfinite(sum(values))
        return PositionTargets(self.names, np.array(values, dtype=np.float64), finite)


def _varint(data: bytes, at: int) -> tuple[int, int]:
    """(value, next offset); raises IndexError past the end, ValueError when too long."""
    value = shift = 0
    while True:
        byte = data[at]
        at += 1
        value |= (byte & 0x7F) << shift
        if byte < 0x80:
            return value, at
        shift += 7
        if shift > 63:
            raise ValueError("varint too long")


def scan_positions(frame: bytes) -> PositionTemplate | None:
    """The template of ``frame`` when it holds nothing but ``motor_positions`` items, each
    exactly ``{name = 1, position = 2}`` in that order; None otherwise."""
    names: list[str] = []
    fixed: list[bytes] = []
    segment_start = at = 0
    try:
        while at < len(frame):
            if frame[at] != 0x0A:  # motor_positions, length-delimited
                return None
            length, body = _varint(frame, at + 1)
            end = body + length
            if frame[body] != 0x0A:  # name, length-delimited
                return None
            name_length, name_at = _varint(frame, body + 1)
            value_tag = name_at + name_length
            if value_tag + 9 != end or end > len(frame) or frame[value_tag] != 0x11:
                return None
            names.append(frame[name_at:value_tag].decode("utf-8"))
            fixed.append(frame[segment_start : value_tag + 1])
            segment_start = at = end
    except (IndexError, ValueError):  # truncated, an over-long varint or a name not UTF-8
        return None
    if not names:
        return None
    return PositionTemplate(tuple(names), tuple(fixed))
