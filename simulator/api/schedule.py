"""Which sensors of one robot are enabled, at which period from when, and which are due at a
step (HLVS semantics).

A sensor is enabled by a ``sensor_time_steps`` request (period 0 disables it) and reported
from the step after the one that enabled it, then every period from the time it was enabled;
a camera's due steps are camera jobs, the others the regular sensors of the measurement, in
the order of their protobuf fields (:class:`~simulator.api.measurement.DuePlan`).
"""

from __future__ import annotations

import logging
from collections.abc import Callable
from typing import Any

from contracts import RobotId
from contracts.robot_api import messages_pb2 as pb
from simulator.api.devices import (
    ACCELEROMETER,
    CAMERA,
    FORCE,
    GYRO,
    POSITION_SENSOR,
    SENSOR_KINDS,
)
from simulator.api.encode import (
    ACCELEROMETERS,
    FORCES,
    GYROS,
    POSITION_SENSORS,
    SensorLayout,
)
from simulator.api.measurement import CameraJob, DuePlan, Measurement

log = logging.getLogger(__name__)

BASIC_TIME_STEP_MS = 8
CAMERA_MIN_TIME_STEP_MS = 16
MAX_LAYOUTS = 64
# protobuf field and number of values of each regular sensor kind (cameras are separate)
_FIELDS = {ACCELEROMETER: (ACCELEROMETERS, 3), FORCE: (FORCES, 1), GYRO: (GYROS, 3)}
_FIELDS[POSITION_SENSOR] = (POSITION_SENSORS, 1)


def rendering_bandwidth_mb_s(width: int, height: int, period_ms: int) -> float:
    """HLVS rendering bandwidth of one camera: w*h*3 bytes per period, in MB/s (2^20)."""
    return width * height * 3 * 1000.0 / period_ms / 2**20


class SensorSchedule:
    """The enabled sensors of ``robot`` (``kinds``: its devices by name) and their due steps.
    ``camera_size`` is its camera's (None: no camera); ``sensor_sources`` the world's batch
    form of the sensors' values, if it has one."""

    def __init__(
        self,
        *,
        robot: RobotId,
        kinds: dict[str, str],
        camera_size: tuple[int, int] | None,
        rendering_quota_mb_s: float,
        sensor_sources: Callable[[RobotId, tuple[str, ...]], Any] | None,
        key: str,
    ) -> None:
        self._robot = robot
        self._kinds = kinds
        self._camera_size = camera_size
        self._rendering_quota_mb_s = rendering_quota_mb_s
        self._sensor_sources = sensor_sources
        self._key = key
        self.periods: dict[str, int] = {}  # name -> period ms, in enabling order
        self.new: set[str] = set()  # enabled during this step, reported from the next
        self._enabled_at: dict[str, int] = {}
        # sensors by (period, start): (period, start, names, positions in enabling order)
        self.groups: list[tuple[int, int, tuple[str, ...], list[int]]] | None = None
        self._order: list[str] = []
        self.cameras: list[tuple[str, int, int]] = []  # (name, period, start)
        self.layouts: dict[tuple[str, ...], DuePlan] = {}

    def set_period(self, name: str, period: int, now_ms: int,
                   warn: Callable[[str], None]) -> bool:  # fmt: skip
        """A ``sensor_time_steps`` request at ``now_ms``: True when the schedule changed; a
        request refused is told with ``warn`` (the league's texts)."""
        kind = self._kinds.get(name)
        if kind is None:
            warn(f'Device "{name}" not found, time step command, ignored.')
            return False
        if kind not in SENSOR_KINDS:
            warn(f'Device "{name}" is not supported, time step command, ignored.')
            return False
        minimum = CAMERA_MIN_TIME_STEP_MS if kind == CAMERA else BASIC_TIME_STEP_MS
        if period == 0:
            self.periods.pop(name, None)
            self.new.discard(name)
            self.groups = None
            return True
        if period < minimum:
            warn(
                f'Time step for "{name}" should be greater or equal to {minimum}, '
                f"ignoring {period} value."
            )
            return False
        if period % BASIC_TIME_STEP_MS:
            warn(
                f'Time step for "{name}" should be a multiple of {BASIC_TIME_STEP_MS}, '
                f"ignoring {period} value."
            )
            return False
        if kind == CAMERA and self._camera_size is not None:
            width, height = self._camera_size
            requested = rendering_bandwidth_mb_s(width, height, period)
            if requested > self._rendering_quota_mb_s:
                warn(
                    "requested rendering bandwidth is above the limit "
                    f"({round(requested)}MB/s > {round(self._rendering_quota_mb_s)}MB/s)"
                )
                return False
        if name not in self.periods:
            self.new.add(name)
        elif self.periods[name] == period:
            return False
        self.periods[name] = period
        self._enabled_at[name] = now_ms
        self.groups = None
        log.debug("%s: %s enabled every %d ms", self._key, name, period)
        return True

    def clear(self) -> None:
        """Every sensor disabled (the robot was removed)."""
        self.periods.clear()
        self.new.clear()
        self.groups = None

    def due(self, out: Measurement, time_ms: int) -> tuple[str, ...]:
        """Due regular sensors (in enabling order); camera jobs added to ``out``. Sensors
        sharing a period and a start are checked as one group."""
        if self.new:
            return self._due_slow(out, time_ms)
        if self.groups is None:
            self._group()
        assert self.groups is not None
        due = [group for group in self.groups if not (time_ms - group[1]) % group[0]]
        for name, period, start in self.cameras:
            if not (time_ms - start) % period:
                self._camera_job(out, name, time_ms)
        if len(due) == 1:
            return due[0][2]
        if not due:
            return ()
        order = self._order
        return tuple([order[i] for i in sorted(i for group in due for i in group[3])])

    def _group(self) -> None:
        groups: dict[tuple[int, int], list[int]] = {}
        self._order = list(self.periods)
        self.cameras = []
        for i, (name, period) in enumerate(self.periods.items()):
            start = self._enabled_at[name]
            if self._kinds[name] == CAMERA:
                self.cameras.append((name, period, start))
            else:
                groups.setdefault((period, start), []).append(i)
        self.groups = [
            (period, start, tuple(self._order[i] for i in members), members)
            for (period, start), members in groups.items()
        ]

    def _due_slow(self, out: Measurement, time_ms: int) -> tuple[str, ...]:
        """:meth:`due` in a step that enabled sensors (those are not reported in it)."""
        new, kinds, enabled_at = self.new, self._kinds, self._enabled_at
        due: list[str] = []
        for name, period in self.periods.items():
            if name in new or (time_ms - enabled_at[name]) % period:
                continue
            if kinds[name] != CAMERA:
                due.append(name)
            else:
                self._camera_job(out, name, time_ms)
        new.clear()
        return tuple(due)

    def _camera_job(self, out: Measurement, name: str, time_ms: int) -> None:
        if self._camera_size is not None:
            width, height = self._camera_size
            camera = pb.CameraMeasurement(name=name, width=width, height=height, quality=-1)
            out.add_camera(CameraJob(self._robot, name, width, height, time_ms, camera))

    def plan(self, due: tuple[str, ...]) -> DuePlan:
        """Due sensors in field-number order (the order of the message) and their layout
        (kept: :attr:`layouts`)."""
        if len(self.layouts) >= MAX_LAYOUTS:
            self.layouts.clear()
        kinds = self._kinds
        names = tuple(sorted(due, key=lambda n: _FIELDS[kinds[n]][0]))  # stable within a kind
        entries = []
        for name in names:
            field, width = _FIELDS[kinds[name]]
            entries.append((field, name, width))
        sources = None
        if self._sensor_sources is not None:
            sources = self._sensor_sources(self._robot, names)
        plan = self.layouts[due] = DuePlan(names, SensorLayout(entries), sources)
        return plan
