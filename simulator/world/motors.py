"""Motor control state of every actuator: position targets with a velocity limit, torque mode,
PID gains, limp robots. Applied to MuJoCo's ``ctrl`` and actuator gains once per basic step.

A position actuator produces ``kp * (ctrl - q) - kv * qdot`` (clipped to the motor's torque
range). Torque mode sets gain 1 and no bias so ``ctrl`` is the torque. Limp robots get zero gain
and bias (only passive joint damping remains). Webots-style PID: ``P`` scales the stiffness
relative to the default ``P = 10`` (``kp = model_kp * P / 10``), ``D`` sets the damping
``kv = model_kp * D / 10`` (N m s/rad; the model's default kv corresponds to ``D = 0.05``);
``I`` is stored but has no effect.
"""

from __future__ import annotations

import logging
import math
from collections.abc import Sequence

import mujoco
import numpy as np
import numpy.typing as npt

from simulator.world.indices import WorldIndex

logger = logging.getLogger(__name__)

FloatArray = npt.NDArray[np.float64]
DEFAULT_P = 10.0


class MotorBank:
    def __init__(self, model: mujoco.MjModel, index: WorldIndex, step_s: float) -> None:
        self._model = model
        self._step_s = step_s
        nu = model.nu
        self.default_kp = np.zeros(nu)
        self.default_kv = np.zeros(nu)
        self.max_torque = np.zeros(nu)
        self.max_velocity = np.zeros(nu)
        self.lower = np.zeros(nu)
        self.upper = np.zeros(nu)
        for robot in index.robots:
            for slot, spec in enumerate(robot.model.motors):
                a = robot.actuators[slot]
                self.default_kp[a] = spec.kp_nm_per_rad
                self.default_kv[a] = spec.kv_nm_s_per_rad
                self.max_torque[a] = spec.max_torque_nm
                self.max_velocity[a] = spec.max_velocity_rad_s
                self.lower[a] = spec.lower_rad
                self.upper[a] = spec.upper_rad
        self.kp = self.default_kp.copy()
        self.kv = self.default_kv.copy()
        self.ki = np.zeros(nu)
        self.velocity_limit = self.max_velocity.copy()
        self.target = np.zeros(nu)
        self.effective = np.zeros(nu)
        self.torque = np.zeros(nu)
        self.torque_mode = np.zeros(nu, dtype=bool)
        self._any_torque = False  # some actuator is in torque mode
        self.limp = np.zeros(nu, dtype=bool)
        self._dirty = True  # gains must be written
        self._ctrl_dirty = True  # ctrl must be written
        self._ramping = True  # some effective target still moves towards its command

    # --- commands ----------------------------------------------------------------------------

    def set_position(self, actuator: int, rad: float) -> None:
        if not math.isfinite(rad):
            logger.debug("ignored non-finite position %r for actuator %d", rad, actuator)
            return
        self.target[actuator] = min(max(rad, self.lower[actuator]), self.upper[actuator])
        self._ramping = True
        if self.torque_mode[actuator]:
            self.torque_mode[actuator] = False
            self._dirty = True

    def set_positions(
        self, actuators: slice | npt.NDArray[np.int64], rads: Sequence[float] | FloatArray
    ) -> None:
        """:meth:`set_position` for distinct ``actuators`` (a slice or an index array) at once;
        non-finite values are ignored."""
        total = rads.sum() if type(rads) is np.ndarray else sum(rads)
        if not math.isfinite(total):  # a NaN or infinity somewhere (or a huge sum)
            values = np.asarray(rads, dtype=np.float64)
            finite = np.isfinite(values)
            chosen = np.arange(len(self.target))[actuators]
            if not finite.all():
                logger.debug("ignored non-finite positions for actuators %s", chosen[~finite])
            actuators, rads = chosen[finite], values[finite]
        if type(actuators) is slice:  # the usual request: clamped straight into the view
            values = np.array(rads, dtype=np.float64)
            np.maximum(values, self.lower[actuators], out=values)
            np.minimum(values, self.upper[actuators], out=self.target[actuators])
        else:
            self.target[actuators] = np.minimum(
                np.maximum(rads, self.lower[actuators]), self.upper[actuators]
            )
        self._targets_changed(actuators)

    def _targets_changed(self, actuators: slice | npt.NDArray[np.int64]) -> None:
        """New position targets for ``actuators``: ramp towards them, out of torque mode."""
        self._ramping = True
        if self._any_torque and self.torque_mode[actuators].any():
            self.torque_mode[actuators] = False
            self._any_torque = bool(self.torque_mode.any())
            self._dirty = True

    def position_writer(self, actuators: npt.NDArray[np.int64]) -> PositionWriter:
        """:meth:`set_positions` for a fixed set of distinct ``actuators`` (their limits
        gathered once): what the robot API writes every step for all robots at once."""
        return PositionWriter(self, actuators)

    def set_velocity(self, actuator: int, rad_s: float) -> None:
        if not math.isfinite(rad_s):
            logger.debug("ignored non-finite velocity %r for actuator %d", rad_s, actuator)
            return
        self.velocity_limit[actuator] = min(abs(rad_s), self.max_velocity[actuator])
        self._ramping = True

    def set_torque(self, actuator: int, nm: float) -> None:
        if not math.isfinite(nm):
            logger.debug("ignored non-finite torque %r for actuator %d", nm, actuator)
            return
        limit = self.max_torque[actuator]
        self.torque[actuator] = min(max(nm, -limit), limit)
        self._ctrl_dirty = True
        if not self.torque_mode[actuator]:
            self.torque_mode[actuator] = True
            self._any_torque = True
            self._dirty = True

    def set_pid(self, actuator: int, p: float, i: float, d: float) -> None:
        if not all(math.isfinite(v) for v in (p, i, d)):
            logger.debug("ignored non-finite PID for actuator %d", actuator)
            return
        base = self.default_kp[actuator] / DEFAULT_P
        self.kp[actuator] = max(p, 0.0) * base
        self.ki[actuator] = i
        self.kv[actuator] = max(d, 0.0) * base
        self._dirty = True

    def set_limp(self, actuators: npt.NDArray[np.int64], limp: bool) -> None:
        self.limp[actuators] = limp
        self._dirty = True

    def hold(self, actuators: npt.NDArray[np.int64], positions: FloatArray) -> None:
        """Position mode at ``positions`` immediately (no ramp): after a teleport or restore."""
        self.target[actuators] = positions
        self.effective[actuators] = positions
        self._ctrl_dirty = True
        if self.torque_mode[actuators].any():
            self.torque_mode[actuators] = False
            self._dirty = True

    # --- per step ----------------------------------------------------------------------------

    def invalidate(self) -> None:
        """Write gains and ``ctrl`` again at the next step (after MuJoCo reset its state)."""
        self._dirty = True
        self._ctrl_dirty = True

    def apply(self, data: mujoco.MjData) -> None:
        """Advance the velocity-limited targets by one basic step and write ``ctrl`` (only when
        something changed: the common case of robots holding a posture costs nothing)."""
        if self._ramping:  # effective = clip(target, effective - reach, effective + reach)
            reach = self.velocity_limit * self._step_s
            effective = self.effective
            low = effective - reach
            np.maximum(self.target, low, out=low)
            np.minimum(low, effective + reach, out=effective)
            self._ramping = not np.array_equal(effective, self.target)
            self._ctrl_dirty = True
        if self._dirty:
            self._write_gains()
        if self._ctrl_dirty:
            if self._any_torque:  # (no actuator is in torque mode while it is False)
                data.ctrl[:] = np.where(self.torque_mode, self.torque, self.effective)
            else:
                data.ctrl[:] = self.effective
            self._ctrl_dirty = False

    def _write_gains(self) -> None:
        active = ~self.limp
        position = active & ~self.torque_mode
        gain = np.where(self.torque_mode, 1.0, self.kp) * active
        self._model.actuator_gainprm[:, 0] = gain
        self._model.actuator_biasprm[:, 1] = -self.kp * position
        self._model.actuator_biasprm[:, 2] = -self.kv * position
        self._dirty = False


class PositionWriter:
    """Position targets of a fixed set of distinct actuators, clamped to limits gathered once;
    the same result as :meth:`MotorBank.set_positions`."""

    __slots__ = ("_bank", "actuators", "_lower", "_upper")

    def __init__(self, bank: MotorBank, actuators: npt.NDArray[np.int64]) -> None:
        self._bank = bank
        self.actuators = actuators
        self._lower = bank.lower[actuators]
        self._upper = bank.upper[actuators]

    def __call__(self, rads: Sequence[float] | FloatArray, *, finite: bool = False) -> None:
        """``finite``: the caller knows that ``rads`` is a float64 array without NaN or
        infinity (checked as they were read), so it is not checked again."""
        bank = self._bank
        if finite:
            values = rads
        else:
            values = np.asarray(rads, dtype=np.float64)
            if not math.isfinite(values.sum()):  # a NaN or infinity (or a huge sum): filtered
                bank.set_positions(self.actuators, values)
                return
        clamped = np.maximum(values, self._lower)
        np.minimum(clamped, self._upper, out=clamped)
        bank.target[self.actuators] = clamped
        bank._targets_changed(self.actuators)
