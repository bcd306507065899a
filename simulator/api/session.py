"""One robot's side of the robot API: commands in, sensor measurements out (HLVS semantics).

A :class:`RobotSession` outlives connections: enabled sensors stay enabled after a disconnect,
as in HLVS. It applies :class:`ActuatorRequests` to the world (warnings for unknown devices and
bad periods are queued for the next measurement), caches motor commands while the robot is limp
and re-applies them when it is released, and builds the :class:`SensorMeasurements` of a step.
Camera images are filled in later by the caller (see :mod:`simulator.api.cameras`).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from contracts import RobotId
from contracts.robot_api import messages_pb2 as pb
from simulator.api.devices import (
    ACCELEROMETER,
    CAMERA,
    GYRO,
    MOTOR,
    POSITION_SENSOR,
    DeviceWorld,
    kind_name,
    robot_key,
)
from simulator.api.fastreq import Notice, PositionTargets, TargetValues
from simulator.api.measurement import DuePlan, Measurement
from simulator.api.schedule import MAX_LAYOUTS, SensorSchedule

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
        self._clock_ms = clock_ms
        self._kinds = {name: kind_name(kind) for name, kind in world.devices(robot).items()}
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
        self._targets_plan = getattr(world, "motor_targets_plan", None)
        # the actuators of the held name list, for batched writes (None: not batchable)
        self._batch_targets: TargetPlan | None = None
        self._valid_names: set[tuple[str, ...]] = set()  # motor name lists known to be fine
        self._pending: list[tuple[int, str]] = []
        self._unsent_warnings = 0  # warnings over MAX_WARNINGS since the last measurement
        self._limp = False
        camera_size: tuple[int, int] | None = None
        if CAMERA in self._kinds.values():
            width, height, _fov = world.camera_info(robot)
            camera_size = (width, height)
        self._schedule = SensorSchedule(
            robot=robot, kinds=self._kinds, camera_size=camera_size,
            rendering_quota_mb_s=rendering_quota_mb_s,
            sensor_sources=getattr(world, "sensor_sources", None), key=self.key,
        )

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
        if self._schedule.set_period(name, period, now_ms, self.warn):
            self._set_steady(None)

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
        return dict(self._schedule.periods)

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
        schedule = self._schedule
        if self._removed():
            schedule.clear()
            self._set_steady(None)
            return out, None
        due = schedule.due(out, time_ms)
        if not due:
            return out, None
        plan = schedule.layouts.get(due)
        if plan is None:
            plan = schedule.plan(due)
        groups = schedule.groups
        if groups is not None and len(groups) == 1 and not schedule.cameras:
            if not schedule.new and not self._pending:
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
