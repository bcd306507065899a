"""Measurements of one catalogue servo in the simulator, against its datasheet and Webots' motor
model: what ``hlvs bench actuators`` prints and what the unit tests check.

Each test builds a one-joint world (a lever on a hinge whose inertia lets the stall torque
accelerate it at ``STALL_ACCEL_RAD_S2``, as a kid-size leg on its servo; no gravity; the robots'
2 ms substeps and 8 ms control step) driven by the same actuator and
:class:`simulator.world.motors.MotorBank` as a robot's joint:

- no-load speed: velocity control at the servo's maximum, the speed after 1.5 s;
- stall torque: velocity control at the maximum against an external load rising slowly (over
  6 s to 1.5 x the stall torque); the line of load against speed, at zero speed;
- position step: Webots' default ``P = 10`` from 0 to 0.3 rad, the trajectory against Webots'
  analytic one (target velocity ``P e``, bounded by the maximum velocity, reached at once):
  the largest difference over the first second, as a share of the step;
- static friction: a limp servo under a slowly rising load; the load at which it starts to turn;
- backlash: a stiff position controller at 0 under a load beyond the static friction, one way
  then the other; the difference of the two positions, less the controller's compliance.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, TypedDict

import mujoco
import numpy as np

from simulator.world.actuator import actuator_xml, joint_attributes
from simulator.world.motors import MotorBank
from simulator.world.robots.model import MotorSpec
from simulator.world.servos import Servo

STEP_S = 0.008
SUBSTEPS = 4
STALL_ACCEL_RAD_S2 = 300.0
STEP_RAD = 0.3
DEFAULT_P = 10.0
SPEC_ERROR = 0.05  # stall torque and no-load speed against the datasheet
STEP_ERROR = 0.10  # position step against Webots' analytic response, share of the step


@dataclass(slots=True)
class Rig:
    model: mujoco.MjModel
    data: mujoco.MjData
    bank: MotorBank

    def run(self, seconds: float, load_nm: Any = None) -> list[tuple[float, float, float]]:
        """Steps ``seconds``; ``load_nm(t)`` is an external torque on the joint. Returns
        (t, q, qdot) after every step."""
        out = []
        for _ in range(int(round(seconds / STEP_S))):
            t = float(self.data.time)
            if load_nm is not None:
                self.data.qfrc_applied[0] = load_nm(t)
            self.bank.apply(self.data)
            mujoco.mj_step(self.model, self.data, nstep=SUBSTEPS)
            out.append((float(self.data.time), float(self.data.qpos[0]), float(self.data.qvel[0])))
        return out


def rig(servo: Servo) -> Rig:
    spec = MotorSpec.from_servo("joint", -math.pi, math.pi, servo)
    xml = f"""<mujoco><option timestep="{STEP_S / SUBSTEPS}" integrator="implicitfast"
 gravity="0 0 0"/>
<worldbody><body name="lever">
 <joint name="joint" type="hinge" axis="0 1 0" {joint_attributes(spec)}
  armature="{servo.stall_torque_nm / STALL_ACCEL_RAD_S2:.6g}"/>
 <geom type="sphere" size="0.01" mass="0.01"/>
</body></worldbody>
<actuator>{actuator_xml("joint", "joint", spec)}</actuator></mujoco>"""
    model = mujoco.MjModel.from_xml_string(xml)
    data = mujoco.MjData(model)
    return Rig(model, data, MotorBank(model, [(0, spec)], STEP_S))


def no_load_speed(servo: Servo) -> float:
    r = rig(servo)
    r.bank.set_position(0, math.inf)
    r.bank.set_velocity(0, servo.no_load_speed_rad_s)
    return r.run(1.5)[-1][2]


def stall_torque(servo: Servo) -> float:
    """The output torque-speed line traced under a rising load, extrapolated to zero speed
    from where the joint turns at 40 % and 10 % of its no-load speed (at rest the joint's
    static friction holds as much as it drives, so the crossing itself is not the stall)."""
    r = rig(servo)
    r.bank.set_position(0, math.inf)
    r.bank.set_velocity(0, servo.no_load_speed_rad_s)
    r.run(0.5)
    top, ramp_s = 1.5 * servo.stall_torque_nm, 6.0
    start = float(r.data.time)

    def load(t: float) -> float:
        return top * min(1.0, (t - start) / ramp_s)

    marks = (0.4 * servo.no_load_speed_rad_s, 0.1 * servo.no_load_speed_rad_s)
    found: list[tuple[float, float]] = []
    previous: tuple[float, float] | None = None
    for t, _q, qdot in r.run(ramp_s, lambda t: -load(t)):
        mark = marks[len(found)]
        if previous is not None and qdot <= mark:
            t0, v0 = previous
            at = t0 + (t - t0) * (v0 - mark) / (v0 - qdot)
            found.append((mark, load(at)))
            if len(found) == len(marks):
                break
        previous = (t, qdot)
    if len(found) < len(marks):
        return top
    (v1, l1), (v2, l2) = found
    return l2 + (l2 - l1) * v2 / (v1 - v2)


def webots_step(t: float, *, p: float, max_velocity: float, step: float) -> float:
    """Webots' position response to a step: the error shrinks at ``min(P e, max_velocity)``."""
    knee = max_velocity / p  # the error below which the controller is no longer saturated
    if step <= knee:
        return step * (1.0 - math.exp(-p * t))
    ramp_s = (step - knee) / max_velocity
    if t <= ramp_s:
        return max_velocity * t
    return step - knee * math.exp(-p * (t - ramp_s))


def step_error(servo: Servo, *, p: float = DEFAULT_P, step: float = STEP_RAD) -> float:
    """Largest difference from Webots' step response over 1 s, as a share of the step."""
    r = rig(servo)
    r.bank.set_pid(0, p, 0.0, 0.0)
    r.bank.set_position(0, step)
    worst = 0.0
    for t, q, _ in r.run(1.0):
        expected = webots_step(t, p=p, max_velocity=servo.no_load_speed_rad_s, step=step)
        worst = max(worst, abs(q - expected))
    return worst / step


def breakaway_torque(servo: Servo) -> float:
    """The load at which a limp servo starts to turn (faster than 2 % of its no-load speed;
    below the static friction MuJoCo's soft friction lets it creep far slower)."""
    r = rig(servo)
    r.bank.set_limp(np.array([0]), True)
    top, ramp_s = 3.0 * max(servo.static_friction_nm, 0.01), 3.0
    moving = 0.02 * servo.no_load_speed_rad_s
    for t, _q, qdot in r.run(ramp_s, lambda t: top * min(1.0, t / ramp_s)):
        if qdot > moving:
            return top * min(1.0, t / ramp_s)
    return top


def backlash(servo: Servo) -> float:
    """The play measured under a load one way then the other, with a stiff controller
    (``P = 100``); the controller's own compliance is removed by measuring at two loads
    beyond the static friction (``f + d`` and ``f + 2 d``) and extrapolating to ``f``."""

    def play(extra: float) -> float:
        r = rig(servo)
        r.bank.set_pid(0, 100.0, 0.0, 0.0)
        r.bank.set_position(0, 0.0)
        load = servo.static_friction_nm + extra
        plus = r.run(0.5, lambda t: load)[-1][1]
        minus = r.run(0.5, lambda t: -load)[-1][1]
        return plus - minus

    extra = 0.05 * servo.stall_torque_nm
    return 2 * play(extra) - play(2 * extra)


class Comparison(TypedDict):
    measured: float
    datasheet: float
    error: float  # relative to the datasheet


class ServoReport(TypedDict):
    servo: str
    no_load_speed_rad_s: Comparison
    stall_torque_nm: Comparison
    static_friction_nm: Comparison
    backlash_rad: Comparison
    step_p10_max_error: float
    ok: bool  # speed, torque and step response within the tolerances


def report(servo: Servo) -> ServoReport:
    """Every measurement of ``servo`` with its datasheet figure and relative error."""

    def compare(measured: float, expected: float) -> Comparison:
        return {
            "measured": round(measured, 5),
            "datasheet": round(expected, 5),
            "error": round(abs(measured - expected) / expected, 4) if expected else 0.0,
        }

    speed = compare(no_load_speed(servo), servo.no_load_speed_rad_s)
    stall = compare(stall_torque(servo), servo.stall_torque_nm)
    friction = compare(breakaway_torque(servo), servo.static_friction_nm)
    play = compare(backlash(servo), servo.backlash_rad)
    step = round(step_error(servo), 4)
    return {
        "servo": servo.id,
        "no_load_speed_rad_s": speed,
        "stall_torque_nm": stall,
        "static_friction_nm": friction,
        "backlash_rad": play,
        "step_p10_max_error": step,
        "ok": speed["error"] <= SPEC_ERROR and stall["error"] <= SPEC_ERROR and step <= STEP_ERROR,
    }
