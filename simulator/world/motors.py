"""Motor control of every actuator as the league's Webots motors behave, with the servo's own
limits (:mod:`simulator.world.actuator` builds the MuJoCo actuator and says why).

Position control (Webots' ``RotationalMotor``): the controller turns the position error into a
target velocity ``v = P e + I integral(e) + D de/dt`` (``P`` default 10, ``I`` and ``D`` 0),
bounded by the velocity limit (``setVelocity``, at most the servo's no-load speed), and the
servo drives the joint towards ``v`` with at most the torque its torque-speed line gives at the
joint's speed. ``setPosition(+-inf)`` is velocity control (the signed ``setVelocity`` value);
``setTorque`` is torque control (clamped to the stall torque, the line still applies); a limp
robot's actuators give no torque (the joint's friction and damping remain).

Backlash: see :mod:`simulator.world.actuator`. Per basic step (``step_ms``)
:meth:`MotorBank.apply` chooses each actuator's mode and writes its
gain, bias and ``ctrl``: unsaturated position control is the affine law
``K (P (target - q) + I integral - (1 + D) qdot)`` evaluated by MuJoCo every substep (exact for
the linear part), saturated position control and velocity control are ``K (v - qdot)``; the
force range is the motor's torque-speed line at the joint's speed.
"""

from __future__ import annotations

import logging
import math
from collections.abc import Sequence

import mujoco
import numpy as np
import numpy.typing as npt

from simulator.world.actuator import ActuatorParams, actuator_params

logger = logging.getLogger(__name__)

FloatArray = npt.NDArray[np.float64]
DEFAULT_P = 10.0  # Webots' default controlPID P (1/s)


class MotorBank:
    """Commands and per-step control of the actuators listed in ``specs`` (actuator id and the
    motor's :class:`simulator.world.robots.model.MotorSpec`); other actuators are left alone."""

    def __init__(
        self, model: mujoco.MjModel, specs: Sequence[tuple[int, object]], step_s: float
    ) -> None:
        self._model = model
        self._step_s = step_s
        nu = model.nu
        params: ActuatorParams = actuator_params(model, specs)
        self.params = params
        self._ids = params.actuators
        self._qpos = params.qpos
        self._dof = params.dof
        self.max_torque = np.zeros(nu)
        self.max_velocity = np.zeros(nu)
        self.lower = np.full(nu, -np.inf)
        self.upper = np.full(nu, np.inf)
        self.max_torque[self._ids] = params.max_torque
        self.max_velocity[self._ids] = params.max_velocity
        self.lower[self._ids] = params.lower
        self.upper[self._ids] = params.upper
        self.p = np.full(nu, DEFAULT_P)
        self.i = np.zeros(nu)
        self.d = np.zeros(nu)
        self.integral = np.zeros(nu)
        self._any_integral = False
        self.velocity_limit = self.max_velocity.copy()
        self.target = np.zeros(nu)
        self.velocity_mode = np.zeros(nu, dtype=bool)
        self.velocity = np.zeros(nu)  # signed, for velocity mode
        self.torque = np.zeros(nu)
        self.torque_mode = np.zeros(nu, dtype=bool)
        self.limp = np.zeros(nu, dtype=bool)
        self.held = np.zeros(nu, dtype=bool)  # held by the world: commands wait
        self.hold_target = np.zeros(nu)
        self._any_held = False
        self._gain = model.actuator_gainprm[:, 0]
        self._bias_q = model.actuator_biasprm[:, 1]
        self._bias_v = model.actuator_biasprm[:, 2]
        self._force_range = model.actuator_forcerange
        self._gain_is_k = False  # gain K of every actuator in ``params`` (the common case)
        self._neg_kp: FloatArray | None = None  # -K P, the position bias (None: P changed)
        self._any_d = False
        self._any_velocity = False
        self._any_torque = False
        self._any_limp = False

    # --- commands ----------------------------------------------------------------------------

    def set_position(self, actuator: int, rad: float) -> None:
        """A position target (clamped to the joint range); ``+-inf`` selects velocity control
        as in Webots; NaN is ignored."""
        if math.isnan(rad):
            logger.debug("ignored NaN position for actuator %d", actuator)
            return
        self.torque_mode[actuator] = False
        if math.isinf(rad):
            self.velocity_mode[actuator] = True
            self._any_velocity = True
            return
        self.velocity_mode[actuator] = False
        self.target[actuator] = min(max(rad, self.lower[actuator]), self.upper[actuator])

    def set_positions(
        self, actuators: slice | npt.NDArray[np.int64], rads: Sequence[float] | FloatArray
    ) -> None:
        """:meth:`set_position` for distinct ``actuators`` (a slice or an index array) at once."""
        values = np.asarray(rads, dtype=np.float64)
        if not math.isfinite(float(values.sum())):  # NaN or infinity somewhere: one by one
            chosen = np.arange(len(self.target))[actuators]
            for actuator, value in zip(chosen.tolist(), values.tolist(), strict=True):
                self.set_position(actuator, value)
            return
        self.target[actuators] = np.minimum(
            np.maximum(values, self.lower[actuators]), self.upper[actuators]
        )
        self._targets_changed(actuators)

    def _targets_changed(self, actuators: slice | npt.NDArray[np.int64]) -> None:
        """New finite position targets for ``actuators``: position control."""
        if self._any_torque:
            self.torque_mode[actuators] = False
            self._any_torque = bool(self.torque_mode.any())
        if self._any_velocity:
            self.velocity_mode[actuators] = False
            self._any_velocity = bool(self.velocity_mode.any())

    def position_writer(self, actuators: npt.NDArray[np.int64]) -> PositionWriter:
        """:meth:`set_positions` for a fixed set of distinct ``actuators`` (their limits
        gathered once): what the robot API writes every step for all robots at once."""
        return PositionWriter(self, actuators)

    def set_velocity(self, actuator: int, rad_s: float) -> None:
        """Webots' ``setVelocity``: the velocity limit of position control (its magnitude, at
        most the servo's no-load speed) and the target of velocity control (signed)."""
        if not math.isfinite(rad_s):
            logger.debug("ignored non-finite velocity %r for actuator %d", rad_s, actuator)
            return
        limit = self.max_velocity[actuator]
        self.velocity_limit[actuator] = min(abs(rad_s), limit)
        self.velocity[actuator] = min(max(rad_s, -limit), limit)

    def set_torque(self, actuator: int, nm: float) -> None:
        if not math.isfinite(nm):
            logger.debug("ignored non-finite torque %r for actuator %d", nm, actuator)
            return
        limit = self.max_torque[actuator]
        self.torque[actuator] = min(max(nm, -limit), limit)
        self.torque_mode[actuator] = True
        self._any_torque = True

    def set_pid(self, actuator: int, p: float, i: float, d: float) -> None:
        """Webots' ``setControlPID``: the gains of the position-to-velocity controller."""
        if not all(math.isfinite(v) for v in (p, i, d)):
            logger.debug("ignored non-finite PID for actuator %d", actuator)
            return
        self.p[actuator] = max(p, 0.0)
        self.i[actuator] = max(i, 0.0)
        self.d[actuator] = max(d, 0.0)
        self.integral[actuator] = 0.0
        self._any_integral = bool(self.i.any())
        self._any_d = bool(self.d.any())
        self._neg_kp = None

    def set_limp(self, actuators: npt.NDArray[np.int64], limp: bool) -> None:
        self.limp[actuators] = limp
        self._any_limp = bool(self.limp.any())

    def set_held(self, actuators: npt.NDArray[np.int64], positions: FloatArray | None) -> None:
        """Hold ``actuators`` at ``positions`` under position control whatever is commanded
        (commands still update the targets, which apply again on release: ``None``)."""
        self.held[actuators] = positions is not None
        if positions is not None:
            self.hold_target[actuators] = positions
        self._any_held = bool(self.held.any())

    def hold(self, actuators: npt.NDArray[np.int64], positions: FloatArray) -> None:
        """Position control at ``positions`` (after a teleport or restore)."""
        self.target[actuators] = positions
        self.integral[actuators] = 0.0
        self._targets_changed(actuators)

    # --- per step ----------------------------------------------------------------------------

    def invalidate(self) -> None:
        """Kept for callers that reset MuJoCo's state: every step writes everything anyway."""

    def apply(self, data: mujoco.MjData) -> None:
        """Choose each actuator's mode and write bias, ``ctrl`` and force range (and the gain
        where a rare mode needs it) for the next basic step, from the joints' positions and
        velocities now. Right after ``mj_step`` each numpy call costs a few microseconds, so the
        common case (every actuator in position control with ``D`` 0, none held or limp) takes
        its own path of about twenty calls; the rare modes take the general one."""
        q = data.qpos[self._qpos]
        qdot = data.qvel[self._dof]
        rare = self._any_held or self._any_integral or self._any_d
        rare = rare or self._any_velocity or self._any_torque or self._any_limp
        if rare:
            self._apply_general(data, q, qdot)
        else:
            self._apply_position(data, q, qdot)
        self._write_force_range(qdot)

    def _apply_position(self, data: mujoco.MjData, q: FloatArray, qdot: FloatArray) -> None:
        """Position control of every actuator with ``I`` and ``D`` 0: the values of
        :meth:`_apply_general` in that case, the gain left at ``K`` (an actuator that gives no
        torque gets ``ctrl`` and bias 0 instead of gain 0: the same force, 0)."""
        ids, par = self._ids, self.params
        if not self._gain_is_k:
            self._gain[ids] = par.gain
            self._gain_is_k = True
        if self._neg_kp is None:
            self._neg_kp = -par.gain * self.p[ids]
        p = self.p[ids]
        target = self.target[ids]
        limit = self.velocity_limit[ids]
        error = target - q
        shift = np.maximum(error, par.minus_half_play)
        np.minimum(shift, par.half_play, out=shift)  # backlash: see the general path
        error -= shift
        wanted = p * error
        free = np.abs(wanted) <= limit  # not saturated
        ctrl = target - shift
        ctrl *= p
        limited = np.copysign(limit, wanted)
        np.copyto(limited, ctrl, where=free)
        # masks as factors (ufuncs: ``np.where`` and ``np.copyto`` dispatch through Python)
        on = error != 0.0  # off: within the play (the shift took the whole error)
        on |= par.no_play
        limited *= on
        free &= on
        self._bias_q[ids] = self._neg_kp * free
        self._bias_v[ids] = par.minus_gain * on
        data.ctrl[ids] = limited

    def _apply_general(self, data: mujoco.MjData, q: FloatArray, qdot: FloatArray) -> None:
        """Every mode: held, integral, velocity, torque, limp, ``D``."""
        ids, par = self._ids, self.params
        self._gain_is_k = False
        p = self.p[ids]
        target = self.target[ids]
        held = self.held[ids] if self._any_held else None
        if held is not None:
            target = np.where(held, self.hold_target[ids], target)
            p = np.where(held, np.maximum(p, DEFAULT_P), p)
        # backlash: within half the play of the target the gears do not touch; beyond it the
        # controller acts on the error less that half
        error = target - q
        shift = np.minimum(np.maximum(error, par.minus_half_play), par.half_play)
        target = target - shift  # (a new array: ``self.target`` keeps the command)
        error -= shift
        wanted = p * error
        pull: FloatArray | float = 0.0
        if self._any_integral:
            self.integral[ids] += error * self._step_s
            pull = self.i[ids] * self.integral[ids]
            wanted += pull
        d = self.d[ids]
        wanted -= d * qdot
        k = par.gain
        limit = self.velocity_limit[ids]
        saturated = np.abs(wanted) > limit
        velocity = self.velocity_mode[ids] if self._any_velocity else None
        if velocity is not None:
            if held is not None:
                velocity = velocity & ~held
            saturated |= velocity
        free = ~saturated
        ctrl = p * target + pull
        ctrl = np.where(saturated, np.copysign(limit, wanted), ctrl)
        if velocity is not None:
            ctrl = np.where(velocity, self.velocity[ids], ctrl)
        gain = k.copy()
        bias_q = -k * p * free
        bias_v = -k - k * d * free
        torque = self.torque_mode[ids] if self._any_torque else None
        if torque is not None:
            if held is not None:
                torque = torque & ~held
            ctrl = np.where(torque, self.torque[ids], ctrl)
            gain[torque] = 1.0
            bias_q[torque] = 0.0
            bias_v[torque] = 0.0
        off = (error == 0.0) & par.has_play  # within the play (the shift took the whole error)
        if velocity is not None:
            off &= ~velocity
        if torque is not None:
            off &= ~torque
        if self._any_limp:
            off |= self.limp[ids]
        gain[off] = 0.0
        bias_q[off] = 0.0
        bias_v[off] = 0.0
        self._gain[ids] = gain
        self._bias_q[ids] = bias_q
        self._bias_v[ids] = bias_v
        data.ctrl[ids] = ctrl

    def _write_force_range(self, qdot: FloatArray) -> None:
        """The torque-speed line at the joint's speed bounds the force for the step: full
        torque against the motion, the line's torque (at least 0) with it. Both bounds in four
        calls: ``(-reach, reach) - slope qdot`` clamped to ``[-T, 0]`` and ``[0, T]`` (moving
        forward the lower bound is below ``-T``, backward the upper one above ``T``)."""
        par = self.params
        bounds = par.line_bounds - (par.line_slope * qdot)[:, None]
        np.minimum(bounds, par.bounds_high, out=bounds)
        np.maximum(bounds, par.bounds_low, out=bounds)
        self._force_range[self._ids] = bounds


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
            if not math.isfinite(values.sum()):  # NaN or infinity: one by one
                bank.set_positions(self.actuators, values)
                return
        clamped = np.maximum(values, self._lower)
        np.minimum(clamped, self._upper, out=clamped)
        bank.target[self.actuators] = clamped
        bank._targets_changed(self.actuators)
