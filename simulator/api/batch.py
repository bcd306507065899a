"""The robot API's per-step work over all robots at once.

With eight robots, the API's cost on the step thread was mostly the same few numpy calls made
once per robot. A :class:`StepBatch` makes them once per step:

- the regular sensors of every measurement of the step: one gather from the world
  (:meth:`simulator.world.World.gather_sensors` over the robots' concatenated
  :meth:`~simulator.world.World.sensor_sources`), one scatter of the values into the
  concatenated wire templates (:class:`simulator.api.encode.SensorLayout`) and one ``tobytes``,
  cut into each robot's bytes;
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
from typing import Any

import numpy as np
import numpy.typing as npt

from simulator.api.fastreq import TargetValues
from simulator.api.session import DuePlan, Measurement, TargetPlan

MAX_COMBINATIONS = 64  # distinct combinations kept (robots enabling sensors at other periods)


class _Encoding:
    __slots__ = ("sources", "template", "byte_index", "bounds")

    def __init__(self, plans: Sequence[DuePlan]) -> None:
        out_q: list[npt.NDArray[np.int64]] = []
        src_q: list[npt.NDArray[np.int64]] = []
        out_s: list[npt.NDArray[np.int64]] = []
        src_s: list[npt.NDArray[np.int64]] = []
        templates: list[npt.NDArray[np.uint8]] = []
        byte_index: list[npt.NDArray[np.int64]] = []
        bounds: list[tuple[int, int]] = []
        values = size = 0
        for plan in plans:
            oq, sq, os_, ss = plan.sources
            out_q.append(oq + values)
            src_q.append(sq)
            out_s.append(os_ + values)
            src_s.append(ss)
            layout = plan.layout
            templates.append(layout.template)
            byte_index.append(layout.byte_index + size)
            bounds.append((size, size + len(layout.template)))
            values += layout.values
            size += len(layout.template)

        def joined(parts: list[npt.NDArray[np.int64]]) -> npt.NDArray[np.int64]:
            return np.concatenate(parts).astype(np.int64) if parts else np.zeros(0, np.int64)

        self.sources = (joined(out_q), joined(src_q), joined(out_s), joined(src_s))
        self.template = np.concatenate(templates)
        self.byte_index = joined(byte_index)
        self.bounds = tuple(bounds)


class StepBatch:
    """Batched sensor encoding and target writes for a world with the batch forms."""

    def __init__(self, world: Any) -> None:
        self._gather = world.gather_sensors
        self._writer = world.motor_targets_writer
        self._encodings: dict[tuple[DuePlan, ...], _Encoding] = {}
        self._targets: dict[tuple[TargetPlan, ...], Callable[[Any], None]] = {}

    @staticmethod
    def supports(world: object) -> bool:
        return all(
            hasattr(world, name)
            for name in ("gather_sensors", "sensor_sources", "motor_targets_writer",
                         "motor_targets_plan")
        )  # fmt: skip

    def encode(self, items: Sequence[tuple[Measurement, DuePlan]]) -> None:
        """Fill ``sensors`` of each measurement with the encoding of its plan (every plan has
        ``sources``)."""
        key = tuple([plan for _, plan in items])
        encoding = self._encodings.get(key)
        if encoding is None:
            if len(self._encodings) >= MAX_COMBINATIONS:
                self._encodings.clear()
            encoding = self._encodings[key] = _Encoding(key)
        values = self._gather(encoding.sources)
        out = encoding.template.copy()
        out[encoding.byte_index] = values.astype("<f8", copy=False).view(np.uint8)
        raw = out.tobytes()
        for (measurement, _), (start, end) in zip(items, encoding.bounds, strict=True):
            measurement.sensors = raw[start:end]

    def set_targets(self, items: Sequence[tuple[TargetPlan, TargetValues]]) -> None:
        """Write the position targets of several robots (distinct actuators) at once."""
        key = tuple([plan for plan, _ in items])
        write = self._targets.get(key)
        if write is None:
            if len(self._targets) >= MAX_COMBINATIONS:
                self._targets.clear()
            write = self._targets[key] = self._writer(np.concatenate([p.actuators for p in key]))
        write(np.concatenate([values for _, values in items]))
