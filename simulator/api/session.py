"""One robot's side of the robot API: commands in, sensor measurements out (HLVS semantics).

A :class:`RobotSession` outlives connections: enabled sensors stay enabled after a disconnect,
as in HLVS. It applies :class:`ActuatorRequests` to the world (warnings for unknown devices and
bad periods are queued for the next measurement), caches motor commands while the robot is limp
and re-applies them when it is released, and builds the :class:`SensorMeasurements` of a step.
Camera images are filled in later by the caller (see :mod:`simulator.api.cameras`).
"""

from __future__ import annotations

import logging
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from contracts import RobotId
from contracts.robot_api import messages_pb2 as pb
from simulator.api.devices import (
    ACCELEROMETER,
    CAMERA,
    FORCE,
    GYRO,
    MOTOR,
    POSITION_SENSOR,
    SENSOR_KINDS,
    DeviceWorld,
    kind_name,
    robot_key,
)
from simulator.api.encode import (
    ACCELEROMETERS,
    FORCES,
    GYROS,
    POSITION_SENSORS,
    SensorLayout,
    varint,
)
from simulator.api.fastreq import Notice, PositionTargets, TargetValues
from simulator.api.framing import HEADER

log = logging.getLogger(__name__)

BASIC_TIME_STEP_MS = 8
MAX_LAYOUTS = 64
# protobuf field and number of values of each regular sensor kind (cameras are separate)
_FIELDS = {ACCELEROMETER: (ACCELEROMETERS, 3), FORCE: (FORCES, 1), GYRO: (GYROS, 3)}
_FIELDS[POSITION_SENSOR] = (POSITION_SENSORS, 1)
CAMERA_MIN_TIME_STEP_MS = 16
WARNING = pb.Message.WARNING_MESSAGE
ERROR = pb.Message.ERROR_MESSAGE
Request = pb.ActuatorRequests | PositionTargets | Notice
# Warnings repeat on every request that earns one, as the league's server sends them
# (``warn`` in controllers/player/player.cpp:213, called per request in processBuffer,
# :452-589, and sent with the next measurement, :709-742), bounded so that a client cannot
# make the server build and send without limit: at most MAX_WARNINGS per measurement (then one
# line telling how many more were not sent), each at most MAX_WARNING_CHARS characters (a
# longer one, such as a 200 kB device name echoed back, keeps its start and its end).
MAX_WARNINGS = 16
MAX_WARNING_CHARS = 240


def rendering_bandwidth_mb_s(width: int, height: int, period_ms: int) -> float:
    """HLVS rendering bandwidth of one camera: w*h*3 bytes per period, in MB/s (2^20)."""
    return width * height * 3 * 1000.0 / period_ms / 2**20


@dataclass(slots=True)
class CameraJob:
    """A camera image owed to a measurement of this robot."""

    robot: RobotId
    name: str
    width: int
    height: int
    time_ms: int
    measurement: pb.CameraMeasurement


class Measurement:
    """One step's measurement: ``time``, ``real_time``, the encoded regular ``sensors`` and the
    camera ``jobs``. The protobuf ``header`` (time, real_time, messages, cameras) is only made
    when a message or a camera needs it; otherwise :meth:`head` is hand-encoded. ``frame``: the
    whole framed message (length prefix, head, sensors) when the step's batch built it (a
    measurement without header), else None."""

    __slots__ = ("time", "real_time", "_sensors", "jobs", "frame", "_header")

    def __init__(self, time: int, real_time: int, sensors: bytes = b"") -> None:
        self.time = time
        self.real_time = real_time
        self._sensors: bytes | None = sensors
        self.jobs: list[CameraJob] = []
        self.frame: bytes | None = None
        self._header: pb.SensorMeasurements | None = None

    @property
    def sensors(self) -> bytes:
        """The encoded regular sensors (cut from ``frame`` when only the frame was built)."""
        if self._sensors is None:
            assert self.frame is not None
            self._sensors = self.frame[HEADER.size + len(self.head()) :]
        return self._sensors

    @sensors.setter
    def sensors(self, value: bytes) -> None:
        self._sensors = value

    def set_frame(self, frame: bytes) -> None:
        """The whole framed message of a measurement without header (its sensors are cut
        from it when asked for)."""
        self.frame = frame
        self._sensors = None

    @property
    def plain(self) -> bool:
        """No header: no message and no camera (the head is :func:`header_bytes`)."""
        return self._header is None

    @property
    def header(self) -> pb.SensorMeasurements:
        if self._header is None:
            self._header = pb.SensorMeasurements(time=self.time, real_time=self.real_time)
        return self._header

    @property
    def message_count(self) -> int:
        return 0 if self._header is None else len(self._header.messages)

    def head(self) -> bytes:
        """The serialized header (everything but the regular sensors)."""
        if self._header is None:
            return header_bytes(self.time, self.real_time)
        return bytes(self._header.SerializeToString())

    def size(self) -> int:
        return len(self.head()) + len(self.sensors)

    def payload(self) -> bytes:
        return self.head() + self.sensors

    def parsed(self) -> pb.SensorMeasurements:
        """The whole measurement as a message (for tests and tools; slow path)."""
        msg = pb.SensorMeasurements()
        msg.ParseFromString(self.payload())
        return msg


_last_head: list[tuple[int, int, bytes]] = [(-1, -1, b"")]  # all robots of a step share it


def header_bytes(time_ms: int, real_time_ms: int) -> bytes:
    """``SensorMeasurements(time=time_ms, real_time=real_time_ms).SerializeToString()``."""
    last = _last_head[0]
    if last[0] == time_ms and last[1] == real_time_ms:
        return last[2]
    if not (0 <= time_ms < 2**32 and 0 <= real_time_ms < 2**64):  # protobuf says what is wrong
        return bytes(
            pb.SensorMeasurements(time=time_ms, real_time=real_time_ms).SerializeToString()
        )
    head = (b"\x08" + varint(time_ms) if time_ms else b"") + (
        b"\x10" + varint(real_time_ms) if real_time_ms else b""
    )
    _last_head[0] = (time_ms, real_time_ms, head)
    return head


class DuePlan:
    """The due regular sensors of a measurement: ``names`` in message order, their wire
    ``layout`` and, when the world has the batch form, where their values come from
    (``sources``, :meth:`simulator.world.World.sensor_sources`). Compared and hashed by
    identity: one object per robot and name list, reused every step."""

    __slots__ = ("names", "layout", "sources")

    def __init__(self, names: tuple[str, ...], layout: SensorLayout, sources: Any) -> None:
        self.names = names
        self.layout = layout
        self.sources = sources


class TargetPlan:
    """The actuators of a robot's held motor name list (distinct names), for
    :meth:`simulator.world.World.motor_targets_writer`. Compared and hashed by identity."""

    __slots__ = ("names", "actuators")

    def __init__(self, names: tuple[str, ...], actuators: Any) -> None:
        self.names = names
        self.actuators = actuators


class SteadyChanges:
    """A count shared by the sessions of one server, raised whenever the steady state of one
    of them changes (:attr:`RobotSession.steady`): a step tells that none changed from one
    number instead of asking every session."""

    __slots__ = ("count",)

    def __init__(self) -> None:
        self.count = 0


class RobotSession:
    """Sensor enabling, command application and measurement building for one robot."""

    def __init__(
        self,
        *,
        robot: RobotId,
        world: DeviceWorld,
        rendering_quota_mb_s: float,
        clock_ms: Callable[[], int],
        steady_changes: SteadyChanges | None = None,
    ) -> None:
        self.robot = robot
        self.steady_changes = steady_changes if steady_changes is not None else SteadyChanges()
        self.key = robot_key(robot)
        self._world = world
        self._rendering_quota_mb_s = rendering_quota_mb_s
        self._clock_ms = clock_ms
        self._kinds = {name: kind_name(kind) for name, kind in world.devices(robot).items()}
        self._sensors: dict[str, int] = {}  # name -> period ms
        self._new_sensors: set[str] = set()  # enabled during this step, reported from the next
        self._enabled_at: dict[str, int] = {}
        self._motor_names = frozenset(n for n, k in self._kinds.items() if k == MOTOR)
        self._positions: dict[str, float] = {}  # last commands, re-applied after a penalty
        # the latest targets of a known name list, not yet merged into _positions
        self._held: tuple[tuple[str, ...], TargetValues] | None = None
        self._velocities: dict[str, float] = {}
        self._torques: dict[str, float] = {}
        # batch forms of the world (simulator.world.World has them; a fake world may not)
        self._read_sensors = getattr(world, "read_sensors", None)
        self._set_positions = getattr(world, "set_motor_positions", None)
        # the world's limp / removed flags, read in place (one list item per step and robot)
        flags = getattr(world, "robot_flags", None)
        self._flags: tuple[list[bool], list[bool], int] | None = (
            flags(robot) if flags is not None else None
        )
        # the due plan while every regular sensor has one period and one start and nothing
        # else is going on (no message, no camera, no sensor just enabled): (period, start, plan)
        self._steady: tuple[int, int, DuePlan] | None = None
        self._sensor_sources = getattr(world, "sensor_sources", None)
        self._targets_plan = getattr(world, "motor_targets_plan", None)
        self._layouts: dict[tuple[str, ...], DuePlan] = {}
        # the actuators of the held name list, for batched writes (None: not batchable)
        self._batch_targets: TargetPlan | None = None
        self._valid_names: set[tuple[str, ...]] = set()  # motor name lists known to be fine
        # sensors by (period, start): (period, start, names, positions in enabling order)
        self._groups: list[tuple[int, int, tuple[str, ...], list[int]]] | None = None
        self._order: list[str] = []
        self._camera_sensors: list[tuple[str, int, int]] = []
        self._pending: list[tuple[int, str]] = []
        self._unsent_warnings = 0  # warnings over MAX_WARNINGS since the last measurement
        self._limp = False
        self._camera_size: tuple[int, int] | None = None
        if CAMERA in self._kinds.values():
            width, height, _fov = world.camera_info(robot)
            self._camera_size = (width, height)

    # --- commands ---------------------------------------------------------------------------

    def warn(self, text: str, *, kind: int = WARNING) -> None:
        """Queue a message for the next measurement: every request that earns a warning gets
        it, as from the league's server, up to :data:`MAX_WARNINGS` per measurement (the
        others are counted and told in one line); errors always go out."""
        if len(text) > MAX_WARNING_CHARS:
            half = (MAX_WARNING_CHARS - 1) // 2
            text = f"{text[:half]}\u2026{text[-half:]}"
        if kind == WARNING and len(self._pending) >= MAX_WARNINGS:
            self._unsent_warnings += 1
            return
        self._pending.append((kind, text))
        self._set_steady(None)

    def apply(self, request: Request, *, step_time_ms: int) -> None:
        """Apply one request; ``step_time_ms`` is the time of the measurement this step sends."""
        world, robot = self._world, self.robot
        if world.is_removed(robot):
            return
        self._apply_one(request, step_time_ms, not world.is_limp(robot))

    def apply_all(
        self, requests: list[Request], *, step_time_ms: int
    ) -> None:
        """:meth:`apply` each request in order, right after :meth:`update_limp` (whose limp flag
        it uses: one world query per step instead of two per request)."""
        if self._removed():
            return
        active = not self._limp
        for request in requests:
            if type(request) is PositionTargets:
                self._apply_positions(request.names, request.values, active)
            else:
                self._apply_one(request, step_time_ms, active)

    def take_targets(
        self, requests: list[Request]
    ) -> tuple[TargetPlan, TargetValues] | None:
        """The usual step, for a batched write: when every request is position targets in the
        held name list, read finite from the wire, and the robot is active, they are taken (the
        last one wins, as in :meth:`apply_all`) and returned with the plan of their actuators;
        the caller writes them (:class:`simulator.api.batch.StepBatch`). Otherwise None and
        nothing is taken: the caller uses :meth:`apply_all`. Called right after
        :meth:`update_limp`."""
        held = self._held
        if held is None or self._limp:
            return None
        plan = self._batch_targets
        if plan is None or plan.names is not held[0]:
            plan = self._plan_targets(held[0])
            if plan is None:
                return None
        names = plan.names
        values: TargetValues | None = None
        for request in requests:
            if type(request) is not PositionTargets or request.names is not names:
                return None
            if not request.finite:  # a NaN or an infinity is filtered robot by robot
                return None
            values = request.values
        if values is None or self._removed():
            return None
        self._held = (names, values)
        return plan, values

    def hold_targets(self, names: tuple[str, ...], values: TargetValues) -> None:
        """Targets of the held name list written for the robot by the server's target board
        (:mod:`simulator.api.board`): held as :meth:`take_targets` holds them."""
        self._held = (names, values)

    def _plan_targets(self, names: tuple[str, ...]) -> TargetPlan | None:
        if self._targets_plan is None or names not in self._valid_names:
            return None
        actuators = self._targets_plan(self.robot, names)
        self._batch_targets = None if actuators is None else TargetPlan(names, actuators)
        return self._batch_targets

    def _apply_positions(
        self, names: tuple[str, ...], values: TargetValues, active: bool
    ) -> None:
        held = self._held
        if held is not None and held[0] is names:  # the usual case: the same name list again
            self._held = (names, values)
            if active:
                self._set_many(names, values)
        elif names in self._valid_names:  # distinct, known motors
            self._merge_held()
            self._held = (names, values)
            if active:
                self._set_many(names, values)
        else:
            self._apply_checked(names, values, active)

    def _apply_one(
        self, request: Request, step_time_ms: int, active: bool
    ) -> None:
        if type(request) is PositionTargets:
            self._apply_positions(request.names, request.values, active)
            return
        if type(request) is Notice:
            self.warn(request.text)
            return
        assert isinstance(request, pb.ActuatorRequests)
        world, robot = self._world, self.robot
        motors = self._motor_names
        present = len(request.ListFields())
        if request.motor_positions:
            present -= 1
            positions = list(request.motor_positions)  # one wrapper per item, read twice
            names = tuple([mp.name for mp in positions])
            self._apply_positions(names, [mp.position for mp in positions], active)
        if not present:  # nothing but position targets (the usual request)
            return
        for mv in request.motor_velocities:
            if mv.name not in motors:
                self.warn(f'Motor "{mv.name}" not found, velocity command ignored.')
                continue
            self._velocities[mv.name] = mv.velocity
            if active:
                world.set_motor_velocity(robot, mv.name, mv.velocity)
        for label, items in (("force", request.motor_forces), ("torque", request.motor_torques)):
            for item in items:
                value = item.force if label == "force" else item.torque
                if item.name not in motors:
                    self.warn(f'Motor "{item.name}" not found, {label} command ignored.')
                    continue
                self._torques[item.name] = value
                if active:
                    world.set_motor_torque(robot, item.name, value)
        for pid in request.motor_pids:
            if pid.name not in motors:
                self.warn(f'Motor "{pid.name}" not found, PID command ignored.')
                continue
            world.set_motor_pid(robot, pid.name, pid.PID.X, pid.PID.Y, pid.PID.Z)
        kinds = self._kinds
        for quality in request.camera_qualities:
            if kinds.get(quality.name) == CAMERA:
                self.warn("CameraQuality is not yet implemented, ignored.")
            else:
                self.warn(f'Camera "{quality.name}" not found, quality command ignored.')
        for exposure in request.camera_exposures:
            if kinds.get(exposure.name) != CAMERA:
                self.warn(f'Camera "{exposure.name}" not found, exposure command ignored.')
        for step in request.sensor_time_steps:
            self._time_step(step.name, step.timeStep, step_time_ms)

    def _merge_held(self) -> None:
        if self._held is not None:
            names, values = self._held
            self._positions.update(zip(names, values, strict=True))
            self._held = None

    def _apply_checked(self, names: tuple[str, ...], values: TargetValues, active: bool) -> None:
        """Position targets with unknown or repeated names (the later target wins)."""
        motors = self._motor_names
        targets: dict[str, float] = {}
        for name, value in zip(names, values, strict=True):
            if name not in motors:
                self.warn(f'Motor "{name}" not found, position command ignored.')
                continue
            targets[name] = value
        if len(targets) == len(names) and len(self._valid_names) < MAX_LAYOUTS:
            self._valid_names.add(names)
        self._merge_held()
        self._positions.update(targets)
        if active and targets:
            self._set_many(tuple(targets), list(targets.values()))

    def _set_many(self, names: tuple[str, ...], values: TargetValues) -> None:
        if self._set_positions is not None:
            self._set_positions(self.robot, names, values)
        else:
            for name, value in zip(names, values, strict=True):
                self._world.set_motor_position(self.robot, name, value)

    def _time_step(self, name: str, period: int, now_ms: int) -> None:
        kind = self._kinds.get(name)
        if kind is None:
            self.warn(f'Device "{name}" not found, time step command, ignored.')
            return
        if kind not in SENSOR_KINDS:
            self.warn(f'Device "{name}" is not supported, time step command, ignored.')
            return
        minimum = CAMERA_MIN_TIME_STEP_MS if kind == CAMERA else BASIC_TIME_STEP_MS
        if period == 0:
            self._sensors.pop(name, None)
            self._new_sensors.discard(name)
            self._groups = None
            self._set_steady(None)
            return
        if period < minimum:
            self.warn(
                f'Time step for "{name}" should be greater or equal to {minimum}, '
                f"ignoring {period} value."
            )
            return
        if period % BASIC_TIME_STEP_MS:
            self.warn(
                f'Time step for "{name}" should be a multiple of {BASIC_TIME_STEP_MS}, '
                f"ignoring {period} value."
            )
            return
        if kind == CAMERA and self._camera_size is not None:
            width, height = self._camera_size
            requested = rendering_bandwidth_mb_s(width, height, period)
            if requested > self._rendering_quota_mb_s:
                self.warn(
                    "requested rendering bandwidth is above the limit "
                    f"({round(requested)}MB/s > {round(self._rendering_quota_mb_s)}MB/s)"
                )
                return
        if name not in self._sensors:
            self._new_sensors.add(name)
        elif self._sensors[name] == period:
            return
        self._sensors[name] = period
        self._enabled_at[name] = now_ms
        self._groups = None
        self._set_steady(None)
        log.debug("%s: %s enabled every %d ms", self.key, name, period)

    def update_limp(self) -> None:
        """Follow the world's limp flag; re-apply cached commands when the robot is released."""
        flags = self._flags
        limp = flags[0][flags[2]] if flags is not None else self._world.is_limp(self.robot)
        if limp == self._limp:
            return
        self._limp = limp
        if limp:
            return
        world, robot = self._world, self.robot
        self._merge_held()
        if self._positions:
            self._set_many(tuple(self._positions), list(self._positions.values()))
        for name, velocity in self._velocities.items():
            world.set_motor_velocity(robot, name, velocity)
        for name, torque in self._torques.items():
            world.set_motor_torque(robot, name, torque)

    # --- measurements -----------------------------------------------------------------------

    @property
    def enabled(self) -> dict[str, int]:
        return dict(self._sensors)

    def measure(self, time_ms: int) -> Measurement:
        """The measurement of the step that ended at ``time_ms`` (camera images still empty)."""
        out, plan = self.begin_measure(time_ms, self._clock_ms())
        if plan is not None:
            out.sensors = self.encode(plan)
        return out

    def begin_measure(self, time_ms: int, real_time_ms: int) -> tuple[Measurement, DuePlan | None]:
        """:meth:`measure` without reading and encoding the regular sensors: the measurement
        (messages and camera jobs in it) and the plan of its due sensors (None when none is
        due), whose encoding goes to ``out.sensors`` (:class:`simulator.api.batch.StepBatch`
        encodes the plans of every robot of a step at once)."""
        steady = self._steady
        if steady is not None and not (time_ms - steady[1]) % steady[0] and not self._removed():
            return Measurement(time_ms, real_time_ms), steady[2]
        out = Measurement(time_ms, real_time_ms)
        if self._pending:
            msg = out.header
            for message_type, text in self._pending:
                msg.messages.add(message_type=message_type, text=text)
            self._pending.clear()
            if self._unsent_warnings:
                msg.messages.add(message_type=WARNING, text=(
                    f"{self._unsent_warnings} more warnings since the last measurement not"
                    f" sent (at most {MAX_WARNINGS} per measurement)."
                ))  # fmt: skip
                self._unsent_warnings = 0
        if self._removed():
            self._sensors.clear()
            self._new_sensors.clear()
            self._groups = None
            self._set_steady(None)
            return out, None
        if self._new_sensors:
            due = self._due_slow(out, time_ms)
        else:
            due = self._due(out, time_ms)
        if not due:
            return out, None
        plan = self._layouts.get(due)
        if plan is None:
            plan = self._layout(due)
        groups = self._groups
        if groups is not None and len(groups) == 1 and not self._camera_sensors:
            if not self._new_sensors and not self._pending:
                self._set_steady((groups[0][0], groups[0][1], plan))
        return out, plan

    @property
    def steady(self) -> tuple[int, int, DuePlan] | None:
        """``(period, start, plan)`` while every regular sensor of the robot has one period and
        one start and nothing else is going on (no message, no camera, no sensor just enabled);
        a new tuple whenever that changes. At a step due by it (``(time - start) % period``
        0), an active robot's :meth:`begin_measure` is a plain measurement and ``plan``.
        Each change raises :attr:`steady_changes`."""
        return self._steady

    def _set_steady(self, steady: tuple[int, int, DuePlan] | None) -> None:
        if steady != self._steady:
            self._steady = steady
            self.steady_changes.count += 1

    def _removed(self) -> bool:
        flags = self._flags
        return flags[1][flags[2]] if flags is not None else self._world.is_removed(self.robot)

    def _due(self, out: Measurement, time_ms: int) -> tuple[str, ...]:
        """Due regular sensors (in enabling order); camera jobs added. Sensors sharing a period
        and a start are checked as one group."""
        if self._groups is None:
            self._group_sensors()
        assert self._groups is not None
        due = [group for group in self._groups if not (time_ms - group[1]) % group[0]]
        for name, period, start in self._camera_sensors:
            if not (time_ms - start) % period:
                self._camera_job(out, name, time_ms)
        if len(due) == 1:
            return due[0][2]
        if not due:
            return ()
        order = self._order
        return tuple([order[i] for i in sorted(i for group in due for i in group[3])])

    def _group_sensors(self) -> None:
        groups: dict[tuple[int, int], list[int]] = {}
        self._order = list(self._sensors)
        self._camera_sensors = []
        for i, (name, period) in enumerate(self._sensors.items()):
            start = self._enabled_at[name]
            if self._kinds[name] == CAMERA:
                self._camera_sensors.append((name, period, start))
            else:
                groups.setdefault((period, start), []).append(i)
        self._groups = [
            (period, start, tuple(self._order[i] for i in members), members)
            for (period, start), members in groups.items()
        ]

    def _due_slow(self, out: Measurement, time_ms: int) -> tuple[str, ...]:
        """:meth:`_due` in a step that enabled sensors (those are not reported in it)."""
        new, kinds, enabled_at = self._new_sensors, self._kinds, self._enabled_at
        due: list[str] = []
        for name, period in self._sensors.items():
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
            camera = out.header.cameras.add(name=name, width=width, height=height, quality=-1)
            out.jobs.append(CameraJob(self.robot, name, width, height, time_ms, camera))

    def _layout(self, due: tuple[str, ...]) -> DuePlan:
        """Due sensors in field-number order (the order of the message) and their layout."""
        if len(self._layouts) >= MAX_LAYOUTS:
            self._layouts.clear()
        kinds = self._kinds
        names = tuple(sorted(due, key=lambda n: _FIELDS[kinds[n]][0]))  # stable within a kind
        entries = []
        for name in names:
            field, width = _FIELDS[kinds[name]]
            entries.append((field, name, width))
        sources = None
        if self._sensor_sources is not None:
            sources = self._sensor_sources(self.robot, names)
        plan = self._layouts[due] = DuePlan(names, SensorLayout(entries), sources)
        return plan

    def encode(self, plan: DuePlan) -> bytes:
        """The regular sensors of ``plan`` read and encoded (one robot; see
        :meth:`begin_measure`)."""
        return plan.layout.encode(self._read(plan.names))

    def _read(self, names: tuple[str, ...]) -> Any:
        if self._read_sensors is not None:
            return self._read_sensors(self.robot, names)
        world, robot, kinds = self._world, self.robot, self._kinds
        values: list[float] = []
        for name in names:
            kind = kinds[name]
            if kind == POSITION_SENSOR:
                values.append(world.read_position(robot, name))
            elif kind == ACCELEROMETER:
                values.extend(world.read_accelerometer(robot))
            elif kind == GYRO:
                values.extend(world.read_gyro(robot))
            else:
                values.append(world.read_force(robot, name))
        return values
