"""Robot devices for the robot API: motors, position sensors, IMUs, foot forces, camera info.

Names are the robot model's device names (:class:`simulator.world.robots.devices.DeviceNames`):
the built-in models answer to the league's sample robot's (``Neck``, ``NeckS``,
``Accelerometer``, ``Gyro``, ``Camera``, ``llb``...), a team model to its manifest's (bit-bots'
Wolfgang: ``HeadPan``, ``HeadPan_sensor``, ``imu accelerometer``, ``imu_head gyro``,
``camera``...). Unknown names raise :class:`simulator.errors.UnknownDeviceError`. Batch forms:
:meth:`DeviceAccess.read_positions` (name -> rad), :meth:`DeviceAccess.read_position_array`
(numpy array in ``motor_names(robot)`` order), :meth:`DeviceAccess.set_motor_positions` (many
targets in one vectorised write) and :meth:`DeviceAccess.read_sensors` (the values of named
sensors as one array, index arrays cached per name list: what the robot API reads each step).
Forms over several robots at once, for the robot API's per-step batches
(:mod:`simulator.api.batch`): :meth:`DeviceAccess.motor_targets_plan` +
:meth:`DeviceAccess.motor_targets_writer` (the targets of many robots in one clamped write) and
:meth:`DeviceAccess.sensor_sources` + :meth:`DeviceAccess.gather_sensors` (the sensors of many
robots in one gather; :meth:`DeviceAccess.sensor_gatherer` makes it one numpy call, for a plan
used every step).

Every read returns the sensor's reading: MuJoCo's value, or with the world's sensor model
(:mod:`simulator.world.sensor_noise`) its noisy copy drawn at the last step.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from functools import partial
from typing import TYPE_CHECKING, Any, cast

import mujoco
import numpy as np
import numpy.typing as npt

from contracts import RobotId
from referee import Vec3
from simulator.errors import UnknownDeviceError
from simulator.world.types import DeviceKind

if TYPE_CHECKING:
    from simulator.world.flat import FlatData
    from simulator.world.indices import RobotIndex, WorldIndex
    from simulator.world.motors import MotorBank, PositionWriter

MAX_PLANS = 256


def _slice_or_array(indices: list[int]) -> slice | npt.NDArray[np.int64]:
    """A slice for consecutive ascending indices (much faster to index with), else an array."""
    if indices and indices == list(range(indices[0], indices[0] + len(indices))):
        return slice(indices[0], indices[0] + len(indices))
    return np.array(indices, dtype=np.int64)


class DeviceAccess:
    """Device methods of :class:`simulator.world.World` (mixed in)."""

    index: WorldIndex
    motors: MotorBank
    data: mujoco.MjData
    limp: list[bool]
    removed: list[bool]
    _sensor_span: FlatData  # the true values of qpos and sensordata, one span
    _readings: npt.NDArray[np.float64]  # what sensors read: the span or its noisy copy
    _device_plans: dict[tuple[str, RobotId, tuple[str, ...]], tuple[Any, ...]]

    def _robot(self, robot: RobotId) -> RobotIndex:
        try:
            return self.index.by_id[robot]
        except KeyError:
            raise UnknownDeviceError(robot=str(robot), name="", kind="robot") from None

    def _actuator(self, robot: RobotId, name: str) -> int:
        r = self._robot(robot)
        slot = r.motor_slot.get(name)
        if slot is None:
            raise UnknownDeviceError(robot=str(robot), name=name, kind="motor")
        return int(r.actuators[slot])

    def devices(self, robot: RobotId) -> dict[str, DeviceKind]:
        """Every device name the robot answers to, and its kind."""
        return self._robot(robot).devices.kinds()

    def motor_names(self, robot: RobotId) -> tuple[str, ...]:
        return self._robot(robot).model.motor_names

    def set_motor_position(self, robot: RobotId, name: str, rad: float) -> None:
        """Target position (clamped to the joint range); leaves torque mode."""
        self.motors.set_position(self._actuator(robot, name), float(rad))

    def set_motor_positions(
        self, robot: RobotId, names: Sequence[str], rads: Sequence[float]
    ) -> None:
        """Several targets at once (same result as :meth:`set_motor_position` for each pair in
        order; a name given twice keeps its last value)."""
        if len(names) != len(rads):
            raise ValueError(f"{len(names)} motor names for {len(rads)} positions")
        key = ("set", robot, tuple(names))
        plans = self._plans()
        plan = plans.get(key)
        if plan is None:
            last = {name: i for i, name in enumerate(names)}  # the last value of a repeated name
            chosen = [self._actuator(robot, name) for name in last]
            plan = plans[key] = (_slice_or_array(chosen), list(last.values()))
        actuators, picks = plan
        if len(picks) != len(rads):
            rads = [rads[i] for i in picks]
        self.motors.set_positions(actuators, rads)

    def motor_targets_plan(
        self, robot: RobotId, names: Sequence[str]
    ) -> npt.NDArray[np.int64] | None:
        """The actuator indices of ``names`` (in order) when they are distinct motors of the
        robot, for :meth:`motor_targets_writer`; None when a name repeats (that list goes through
        :meth:`set_motor_positions`, which keeps the last value). Unknown names raise
        :class:`UnknownDeviceError`."""
        if len(set(names)) != len(names):
            return None
        return np.array([self._actuator(robot, name) for name in names], dtype=np.int64)

    def motor_targets_writer(
        self, actuators: npt.NDArray[np.int64]
    ) -> PositionWriter:
        """A writer of position targets for distinct ``actuators`` (of one or many robots,
        from :meth:`motor_targets_plan`, concatenated): one clamped write with the same result
        as :meth:`set_motor_positions` robot by robot."""
        return self.motors.position_writer(actuators)

    def set_motor_velocity(self, robot: RobotId, name: str, rad_s: float) -> None:
        """Maximum velocity of the position controller (clamped to the motor's maximum)."""
        self.motors.set_velocity(self._actuator(robot, name), float(rad_s))

    def set_motor_torque(self, robot: RobotId, name: str, nm: float) -> None:
        """Switch the motor to torque control with this torque (clamped to its range)."""
        self.motors.set_torque(self._actuator(robot, name), float(nm))

    def set_motor_pid(self, robot: RobotId, name: str, p: float, i: float, d: float) -> None:
        self.motors.set_pid(self._actuator(robot, name), float(p), float(i), float(d))

    def read_position(self, robot: RobotId, sensor_name: str) -> float:
        """Joint angle (rad) of a position sensor (``NeckS``; the motor's name is accepted
        too)."""
        r = self._robot(robot)
        slot = r.position_slot.get(sensor_name, r.motor_slot.get(sensor_name))
        if slot is None:
            raise UnknownDeviceError(robot=str(robot), name=sensor_name, kind="position sensor")
        return float(self._readings[self._sensor_span.offset("qpos") + int(r.motor_qpos[slot])])

    def _joint_readings(self, r: RobotIndex) -> npt.NDArray[np.float64]:
        return self._readings[self._sensor_span.offset("qpos") + r.motor_qpos]

    def read_position_array(self, robot: RobotId) -> npt.NDArray[np.float64]:
        """Every joint angle (rad) in ``motor_names(robot)`` order."""
        return np.asarray(self._joint_readings(self._robot(robot)), dtype=np.float64)

    def read_positions(self, robot: RobotId) -> dict[str, float]:
        """``{"NeckS": rad, ...}`` for every position sensor (by its device name)."""
        r = self._robot(robot)
        values = self._joint_readings(r).tolist()
        return dict(zip(r.devices.position_sensors, values, strict=True))

    def read_sensors(self, robot: RobotId, names: Sequence[str]) -> npt.NDArray[np.float64]:
        """The values of ``names`` in order, flat: one per position and force sensor, three
        per accelerometer and gyro (x, y, z)."""
        return self.gather_sensors(self.sensor_sources(robot, names))

    def sensor_sources(
        self, robot: RobotId, names: Sequence[str]
    ) -> tuple[npt.NDArray[np.int64], ...]:
        """Where the values of :meth:`read_sensors` come from: ``(out_q, src_q, out_s, src_s)``,
        value ``out_q[k]`` is ``qpos[src_q[k]]`` and ``out_s[k]`` is ``sensordata[src_s[k]]``.
        The plans of several robots concatenate (``out`` indices shifted) into one
        :meth:`gather_sensors`. Cached per name list."""
        key = ("read", robot, tuple(names))
        plans = self._plans()
        plan = plans.get(key)
        if plan is None:
            plan = self._sensor_plan(robot, names)
            plans[key] = plan
        return plan

    def gather_sensors(
        self, sources: tuple[npt.NDArray[np.int64], ...]
    ) -> npt.NDArray[np.float64]:
        """The values of a :meth:`sensor_sources` plan (or of several concatenated), flat."""
        out_q, src_q, out_s, src_s = sources
        out = np.empty(len(out_q) + len(out_s))
        span, values = self._sensor_span, self._readings
        out[out_q] = values[span.offset("qpos") + src_q]
        out[out_s] = values[span.offset("sensordata") + src_s]
        return out

    def sensor_gatherer(
        self, sources: tuple[npt.NDArray[np.int64], ...]
    ) -> Callable[[], npt.NDArray[np.float64]]:
        """:meth:`gather_sensors` of one plan as one ``take`` from a span over ``qpos`` and
        ``sensordata`` (:class:`simulator.world.flat.FlatData`): one numpy call per step, where
        :meth:`gather_sensors` makes five, each a few microseconds right after ``mj_step``.
        The span is the noisy readings' when the sensor model is not ideal."""
        out_q, src_q, out_s, src_s = sources
        flat = self._sensor_span
        index = np.empty(len(out_q) + len(out_s), dtype=np.intp)
        index[out_q] = flat.indices("qpos", src_q)
        index[out_s] = flat.indices("sensordata", src_s)
        return cast(Callable[[], npt.NDArray[np.float64]], partial(self._readings.take, index))

    def _sensor_plan(
        self, robot: RobotId, names: Sequence[str]
    ) -> tuple[npt.NDArray[np.int64], ...]:
        r = self._robot(robot)
        out_q: list[int] = []
        src_q: list[int] = []
        out_s: list[int] = []
        src_s: list[int] = []
        for name in names:
            at = len(out_q) + len(out_s)
            adr = r.imu_sensors.get(name)
            if adr is not None:
                out_s.extend((at, at + 1, at + 2))
                src_s.extend((adr, adr + 1, adr + 2))
            elif name in r.forces:
                out_s.append(at)
                src_s.append(r.forces[name])
            else:
                slot = r.position_slot.get(name, r.motor_slot.get(name))
                if slot is None:
                    raise UnknownDeviceError(robot=str(robot), name=name, kind="sensor")
                out_q.append(at)
                src_q.append(int(r.motor_qpos[slot]))
        return tuple(np.array(v, dtype=np.int64) for v in (out_q, src_q, out_s, src_s))

    def _plans(
        self,
    ) -> dict[tuple[str, RobotId, tuple[str, ...]], tuple[Any, ...]]:
        """Index arrays per (operation, robot, names), built on first use."""
        try:
            plans = self._device_plans
        except AttributeError:
            plans = self._device_plans = {}
        if len(plans) > MAX_PLANS:  # clients choose the name lists: keep the cache bounded
            plans.clear()
        return plans

    def _vec3(self, adr: int) -> Vec3:
        start = self._sensor_span.offset("sensordata") + adr
        x, y, z = self._readings[start : start + 3].tolist()
        return (x, y, z)

    def read_accelerometer(self, robot: RobotId) -> Vec3:
        """Proper acceleration in the first IMU's frame (the torso's), m/s^2 (+9.81 on z when
        standing still)."""
        return self._vec3(self._robot(robot).accelerometer)

    def read_gyro(self, robot: RobotId) -> Vec3:
        """Angular velocity in the first IMU's frame (the torso's), rad/s."""
        return self._vec3(self._robot(robot).gyro)

    def read_force(self, robot: RobotId, name: str) -> float:
        """Normal force (N) of one force sensor (a sole corner: ``llb`` ... ``rrb``)."""
        r = self._robot(robot)
        adr = r.forces.get(name)
        if adr is None:
            raise UnknownDeviceError(robot=str(robot), name=name, kind="force sensor")
        return float(self._readings[self._sensor_span.offset("sensordata") + adr])

    def camera_info(self, robot: RobotId) -> tuple[int, int, float]:
        """(width, height, horizontal field of view in rad) of the head camera."""
        cam = self._robot(robot).model.camera
        return cam.width, cam.height, cam.fov_rad

    def robot_flags(self, robot: RobotId) -> tuple[list[bool], list[bool], int]:
        """``(limp, removed, i)``: the world's flag lists (changed in place by referee
        commands, never replaced) and the robot's index in them: ``limp[i]`` is
        :meth:`is_limp`, ``removed[i]`` :meth:`is_removed`."""
        return self.limp, self.removed, self._robot(robot).number

    def is_limp(self, robot: RobotId) -> bool:
        return self.limp[self._robot(robot).number]

    def is_removed(self, robot: RobotId) -> bool:
        return self.removed[self._robot(robot).number]
