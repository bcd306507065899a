"""The robot API's per-step work over all robots at once.

With eight robots, the API's cost on the step thread was mostly the same few numpy calls made
once per robot. A :class:`StepBatch` makes them once per step:

- the regular sensors of every measurement of the step: one gather from the world
  (:meth:`simulator.world.World.sensor_gatherer` over the robots' concatenated
  :meth:`~simulator.world.World.sensor_sources`), then one scatter of the values and
  one write of the step's head (time, real time) into a copy of the concatenated framed
  templates (length prefix, head, :class:`simulator.api.encode.SensorLayout`; the fixed bytes
  are in the template), cut into each robot's framed message. The two parts can run on two
  threads (:meth:`StepBatch.gather` reads the world on the step thread; the I/O thread writes
  the bytes with :meth:`Gathered.write` while the next step is computed);
- the position targets of every robot that sent the usual request (the same motor names as
  before, robot active): one clamped write (:meth:`simulator.world.World.motor_targets_writer`;
  the I/O thread made each robot's targets an array as it read them).

The concatenated plans are cached per combination of robot plans (the plans are reused every
step and hashed by identity), so a step only looks one up. The bytes and targets are exactly
those of the robot-by-robot calls (:meth:`simulator.api.session.RobotSession.measure`,
:meth:`~simulator.api.session.RobotSession.apply_all`).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING, Any, TypeVar

import numpy as np
import numpy.typing as npt

from simulator.api.fastreq import TargetValues
from simulator.api.framing import HEADER
from simulator.api.measurement import DuePlan, Measurement
from simulator.api.session import TargetPlan

if TYPE_CHECKING:
    from simulator.world.motors import PositionWriter

K = TypeVar("K")
V = TypeVar("V")

MAX_COMBINATIONS = 64  # distinct combinations kept (robots enabling sensors at other periods)


class Encoding:
    """The concatenated plans of one combination of robots. Each robot's span is
    ``[4-byte length][head][sensors]`` with room for a head of ``head_size`` bytes (the same
    for every robot of a step): the framed messages of robots without messages or cameras are
    cut out whole; the others take their sensors only."""

    __slots__ = ("gather", "template", "byte_index", "rows", "head_index", "head_size",
                 "frames_at", "sensors", "_reused")  # fmt: skip

    def __init__(
        self,
        plans: Sequence[DuePlan],
        head_size: int,
        gatherer: Callable[[Any], Callable[[], npt.NDArray[np.float64]]],
    ) -> None:
        out_q: list[npt.NDArray[np.int64]] = []
        src_q: list[npt.NDArray[np.int64]] = []
        out_s: list[npt.NDArray[np.int64]] = []
        src_s: list[npt.NDArray[np.int64]] = []
        templates: list[npt.NDArray[np.uint8]] = []
        byte_index: list[npt.NDArray[np.int64]] = []
        head_index: list[npt.NDArray[np.int64]] = []
        frames: list[tuple[int, int]] = []
        sensors: list[tuple[int, int]] = []
        values = size = 0
        for plan in plans:
            oq, sq, os_, ss = plan.sources
            out_q.append(oq + values)
            src_q.append(sq)
            out_s.append(os_ + values)
            src_s.append(ss)
            layout = plan.layout
            length = head_size + len(layout.template)
            templates.append(np.frombuffer(HEADER.pack(length), dtype=np.uint8))
            head_index.append(np.arange(size + HEADER.size, size + HEADER.size + head_size))
            templates.append(np.zeros(head_size, dtype=np.uint8))
            start = size + HEADER.size + head_size
            templates.append(layout.template)
            byte_index.append(layout.byte_index + start)
            frames.append((size, start + len(layout.template)))
            sensors.append((start, start + len(layout.template)))
            values += layout.values
            size = start + len(layout.template)

        def joined(parts: list[npt.NDArray[np.int64]]) -> npt.NDArray[np.int64]:
            return np.concatenate(parts).astype(np.int64) if parts else np.zeros(0, np.int64)

        # the values of every robot's due sensors in order: one call per step
        self.gather = gatherer((joined(out_q), joined(src_q), joined(out_s), joined(src_s)))
        # the wire bytes: the fixed ones in place; each step writes values and heads into a
        # copy (steps may be written on the I/O thread while the next one is gathered)
        self.template = np.concatenate(templates)
        self.template.flags.writeable = False
        self.byte_index = joined(byte_index)
        self.head_size = head_size
        spans = {end - start for start, end in frames}
        # robots with the same sensors: the heads are one strided view of the rows
        self.rows = len(plans) if len(spans) == 1 else 0
        self.head_index = joined(head_index).reshape(len(plans), head_size)
        self.frames_at = tuple(frames)
        self.sensors = tuple(sensors)
        self._reused: npt.NDArray[np.uint8] | None = None  # :meth:`frames_in_place`'s buffer

    def write(
        self, values: npt.NDArray[np.float64], head: bytes, measurements: Sequence[Measurement]
    ) -> None:
        """Write one step's ``values`` (from :attr:`gather`) and ``head`` into a copy of the
        template and give each measurement its frame (a plain one) or its sensors."""
        raw = self._raw(values, head)
        for measurement, frame, sensors in zip(
            measurements, self.frames_at, self.sensors, strict=True
        ):
            if measurement.plain:
                measurement.set_frame(raw[frame[0] : frame[1]])
            else:
                measurement.sensors = raw[sensors[0] : sensors[1]]

    def frames(self, values: npt.NDArray[np.float64], head: bytes) -> list[bytes]:
        """Every robot's framed message of one step, all plain (no message, no camera)."""
        raw = self._raw(values, head)
        return [raw[start:end] for start, end in self.frames_at]

    def frames_in_place(self, values: npt.NDArray[np.float64], head: bytes) -> memoryview:
        """:meth:`frames` written into one buffer kept from step to step (no copy of the
        template, no bytes made): the concatenated frames, cut at :attr:`frames_at`. The
        caller is done with it before the next call (plain lockstep sends it at once; what a
        socket does not take is copied)."""
        array = self._reused
        if array is None:
            array = self._reused = self.template.copy()
        self._fill(array, values, head)
        return array.data

    def _raw(self, values: npt.NDArray[np.float64], head: bytes) -> bytes:
        """The concatenated frames of one step: ``values`` and ``head`` written into a copy
        of the template."""
        array = self.template.copy()
        self._fill(array, values, head)
        return array.tobytes()

    def _fill(
        self, array: npt.NDArray[np.uint8], values: npt.NDArray[np.float64], head: bytes
    ) -> None:
        """Write one step's ``values`` and ``head`` into ``array`` (the template's bytes)."""
        array[self.byte_index] = values.astype("<f8", copy=False).view(np.uint8)
        if head:
            head_bytes = np.frombuffer(head, dtype=np.uint8)
            if self.rows:
                size = self.head_size
                array.reshape(self.rows, -1)[:, HEADER.size : HEADER.size + size] = head_bytes
            else:
                array[self.head_index] = head_bytes


class Gathered:
    """One step's sensor values read from the world, not yet written as wire bytes:
    :meth:`write` (on any thread: the world is not read again) fills the measurements."""

    __slots__ = ("encoding", "_values", "_head", "_measurements")

    def __init__(
        self,
        encoding: Encoding,
        values: npt.NDArray[np.float64],
        head: bytes,
        measurements: list[Measurement],
    ) -> None:
        self.encoding = encoding
        self._values = values
        self._head = head
        self._measurements = measurements

    def write(self) -> None:
        self.encoding.write(self._values, self._head, self._measurements)


def _cached(cache: dict[K, V], key: K, build: Callable[[], V]) -> V:
    """``cache[key]``, built on first use; the cache is emptied when it holds
    ``MAX_COMBINATIONS`` (clients choose their sensors: it stays bounded)."""
    value = cache.get(key)
    if value is None:
        if len(cache) >= MAX_COMBINATIONS:
            cache.clear()
        value = cache[key] = build()
    return value


class StepBatch:
    """Batched sensor encoding and target writes for a world with the batch forms."""

    def __init__(self, world: Any) -> None:
        self._gatherer = world.sensor_gatherer
        self._writer = world.motor_targets_writer
        self._encodings: dict[tuple[tuple[DuePlan, ...], int], Encoding] = {}
        self._targets: dict[tuple[TargetPlan, ...], PositionWriter] = {}

    @staticmethod
    def supports(world: object) -> bool:
        return all(
            hasattr(world, name)
            for name in ("sensor_gatherer", "sensor_sources", "motor_targets_writer",
                         "motor_targets_plan")
        )  # fmt: skip

    def encode(self, items: Sequence[tuple[Measurement, DuePlan]], head: bytes) -> None:
        """Fill ``sensors`` of each measurement with the encoding of its plan (every plan has
        ``sources``), and ``frame`` of those without header (``head``: the step's
        :func:`~simulator.api.measurement.header_bytes`)."""
        self.gather(items, head).write()

    def gather(self, items: Sequence[tuple[Measurement, DuePlan]], head: bytes) -> Gathered:
        """:meth:`encode` in two parts: the values are read from the world now, the bytes
        are written by the result's :meth:`Gathered.write`."""
        encoding = self.encoding(tuple([plan for _, plan in items]), len(head))
        return Gathered(encoding, encoding.gather(), head, [m for m, _ in items])

    def encoding(self, plans: tuple[DuePlan, ...], head_size: int) -> Encoding:
        """The concatenated ``plans`` with room for a head of ``head_size`` bytes (cached)."""
        return _cached(
            self._encodings,
            (plans, head_size),
            lambda: Encoding(plans, head_size, self._gatherer),
        )

    def set_targets(self, items: Sequence[tuple[TargetPlan, TargetValues]]) -> None:
        """Write the position targets of several robots (distinct actuators) at once."""
        write = self.targets_writer(tuple([plan for plan, _ in items]))
        # every robot's values were read finite (:meth:`RobotSession.take_targets`)
        write(np.concatenate([values for _, values in items]), finite=True)

    def targets_writer(self, plans: tuple[TargetPlan, ...]) -> PositionWriter:
        """The writer of the concatenated targets of ``plans`` (cached)."""
        return _cached(
            self._targets, plans, lambda: self._writer(np.concatenate([p.actuators for p in plans]))
        )
