"""The servo as a MuJoCo actuator: how a :class:`MotorSpec` becomes MJCF and the constants
:class:`simulator.world.motors.MotorBank` needs each step.

Construction (chosen by measurement, ``hlvs bench actuators`` and ``hlvs bench sim``): one
``<general>`` actuator per joint with an affine bias, ``force = gain ctrl + b1 q + b2 qdot``,
rewritten once per basic step by the motor bank: a velocity servo ``K (v - qdot)``, or while the
P controller is not saturated the exact linear law ``K (P (target - q) - qdot)``, and a force
range rewritten at the same time from the servo's torque-speed line at the joint's speed.

Measured alternative: the line itself as the actuator's affine law (``reach - slope qdot``, a DC
motor at full voltage) whenever the servo asks for more than the line gives. It is integrated
implicitly (stable for any link), but while it acts the servo's velocity feedback does not, so a
position step missed the Webots trajectory by 16-77 % of the step on a light test lever
(against 1-6 % with the force range for the MX and X servos on the same lever, 4 % for every
catalogue servo on the lever of ``hlvs bench actuators``); the force range is what runs. Its
limit: a link so light that the line's slope times the 8 ms step exceeds the link's inertia
(``slope dt / I > 1``, far below any robot link with its servo's armature) chatters near the
no-load speed.

Backlash (position control): within half the gear play of the target the gears do not touch
and the servo gives no torque; beyond it the controller acts on the error less that half, so a
load moves the joint across the whole play and holds it at the far side, as a real gear train
does (decided once per basic step; the 8 ms step resolves the play's statics, not its rattle).
Friction and damping are the joint's ``frictionloss`` and ``damping``; the motor's line is
raised by both so that the output follows the datasheet: stall torque at rest, zero torque at
the no-load speed. ``K`` (N m s/rad) makes the servo saturate at 5 % of its no-load speed of
velocity error, stiff enough to track the Webots model and soft enough for 2 ms substeps.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any
from xml.sax.saxutils import quoteattr

import mujoco
import numpy as np
import numpy.typing as npt

if TYPE_CHECKING:
    from simulator.world.robots.model import MotorSpec

GAIN_PER_NO_LOAD = 20.0  # K = 20 x motor torque / no-load speed: saturates at 5 % speed error
IntArray = npt.NDArray[np.int64]
FloatArray = npt.NDArray[np.float64]


@dataclass(frozen=True, slots=True)
class LineConstants:
    """The motor's own torque-speed line, raised so the output (after the joint's friction
    and damping) is the datasheet's: ``drive(w) = motor_torque * clip((line_speed - |w|) /
    line_span, 0, 1)`` capped at ``motor_torque``."""

    motor_torque_nm: float
    line_speed_rad_s: float
    line_span_rad_s: float
    gain_nm_s_per_rad: float


def line_constants(spec: MotorSpec) -> LineConstants:
    stall, no_load = spec.max_torque_nm, spec.max_velocity_rad_s
    friction, damping = spec.static_friction_nm, spec.damping_nm_s_per_rad
    corner = spec.full_torque_speed_rad_s
    motor = stall + friction
    share = (friction + damping * no_load) / motor  # of the motor torque lost at no-load speed
    if share >= 1.0:
        raise ValueError(
            f"{spec.name}: friction {friction} N m and damping {damping} N m s/rad exceed the "
            f"stall torque {stall} N m before the no-load speed {no_load} rad/s"
        )
    line_speed = (no_load - share * corner) / (1.0 - share)
    return LineConstants(
        motor_torque_nm=motor,
        line_speed_rad_s=line_speed,
        line_span_rad_s=line_speed - corner,
        gain_nm_s_per_rad=GAIN_PER_NO_LOAD * motor / no_load,
    )


def actuator_xml(name: str, joint: str, spec: MotorSpec) -> str:
    """The ``<general>`` actuator of one motor (gains and range are rewritten every step)."""
    c = line_constants(spec)
    k = c.gain_nm_s_per_rad
    t = c.motor_torque_nm
    return (
        f'<general name={quoteattr(name)} joint={quoteattr(joint)} gaintype="fixed" '
        f'biastype="affine" gainprm="{k:.6g}" biasprm="0 0 {-k:.6g}" ctrllimited="false" '
        f'forcelimited="true" forcerange="{-t:.6g} {t:.6g}"/>'
    )


def joint_attributes(spec: MotorSpec) -> str:
    """The joint's friction and damping from its servo (MJCF attributes)."""
    return f'damping="{spec.damping_nm_s_per_rad:.6g}" frictionloss="{spec.static_friction_nm:.6g}"'


@dataclass(frozen=True, slots=True)
class ActuatorParams:
    """Per-actuator constants, in the order of ``actuators`` (a slice when consecutive)."""

    actuators: Any  # slice | IntArray
    qpos: Any  # slice | IntArray
    dof: Any
    max_torque: FloatArray
    max_velocity: FloatArray
    lower: FloatArray
    upper: FloatArray
    line_slope: FloatArray  # N m per rad/s
    gain: FloatArray
    half_play: FloatArray  # half the backlash, rad
    minus_half_play: FloatArray
    has_play: npt.NDArray[np.bool_]
    no_play: npt.NDArray[np.bool_]
    minus_gain: FloatArray  # -K, the velocity bias of position control
    # (n, 2): -reach, reach (the force range before the clamps; reach: the line's torque
    # extrapolated to zero speed, at least the motor torque)
    line_bounds: FloatArray
    bounds_low: FloatArray  # (n, 2): -motor torque, 0
    bounds_high: FloatArray  # (n, 2): 0, motor torque


def _compact(values: list[int]) -> slice | IntArray:
    if values and values == list(range(values[0], values[0] + len(values))):
        return slice(values[0], values[0] + len(values))
    return np.array(values, dtype=np.int64)


def actuator_params(model: mujoco.MjModel, specs: Sequence[tuple[int, Any]]) -> ActuatorParams:
    """Constants of the actuators in ``specs`` (actuator id, :class:`MotorSpec`), sorted by id."""
    ordered = sorted(specs, key=lambda pair: pair[0])
    ids = [a for a, _ in ordered]
    joints = [int(model.actuator_trnid[a, 0]) for a in ids]
    constants = [line_constants(spec) for _, spec in ordered]

    def array(values: list[float]) -> FloatArray:
        return np.array(values, dtype=np.float64)

    torque = array([c.motor_torque_nm for c in constants])
    reach = array([c.motor_torque_nm * c.line_speed_rad_s / c.line_span_rad_s for c in constants])
    zero = np.zeros_like(torque)
    gain = array([c.gain_nm_s_per_rad for c in constants])
    return ActuatorParams(
        actuators=_compact(ids),
        qpos=_compact([int(model.jnt_qposadr[j]) for j in joints]),
        dof=_compact([int(model.jnt_dofadr[j]) for j in joints]),
        max_torque=array([s.max_torque_nm for _, s in ordered]),
        max_velocity=array([s.max_velocity_rad_s for _, s in ordered]),
        lower=array([s.lower_rad for _, s in ordered]),
        upper=array([s.upper_rad for _, s in ordered]),
        line_slope=array([c.motor_torque_nm / c.line_span_rad_s for c in constants]),
        gain=gain,
        half_play=array([s.backlash_rad / 2 for _, s in ordered]),
        minus_half_play=array([-s.backlash_rad / 2 for _, s in ordered]),
        has_play=np.array([s.backlash_rad > 0 for _, s in ordered], dtype=bool),
        no_play=np.array([s.backlash_rad <= 0 for _, s in ordered], dtype=bool),
        minus_gain=-gain,
        line_bounds=np.stack([-reach, reach], axis=1),
        bounds_low=np.stack([-torque, zero], axis=1),
        bounds_high=np.stack([zero, torque], axis=1),
    )
