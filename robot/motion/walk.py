"""Open-loop walking gait for the built-in robots.

A cycle of ``period_s`` holds two steps: the left foot swings in the first half, the right foot
in the second. The torso sways over the support foot (feet shifted sideways in the torso frame),
the swing foot is lifted on a half sine and carried forward with a cosine ease, the support foot
slides back linearly, so the torso advances at the commanded speed. Foot positions go through
the analytic leg IK; an optional gyro term damps pitch and roll oscillations.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

from robot.motion.ik import FootTarget, leg_ik
from robot.motion.imu import AttitudeFilter
from robot.motion.models import RobotKinematics, kinematics

Vec3 = tuple[float, float, float]


@dataclass(frozen=True, slots=True, kw_only=True)
class WalkParams:
    """Gait parameters (lengths in metres, times in seconds, angles in radians)."""

    period_s: float = 0.56
    double_support_ratio: float = 0.2
    step_height_m: float = 0.03
    sway_m: float = 0.022
    sway_phase_lead: float = 0.05  # fraction of a cycle the sway leads the swing
    hip_height_m: float = 0.19  # hip joint above the sole while standing
    foot_x_offset_m: float = -0.005
    foot_y_offset_m: float = 0.012  # added to the hip offset, per foot
    torso_pitch_rad: float = 0.15  # forward lean
    walk_lean_rad: float = 0.0  # more forward lean while stepping (at the full gait amplitude)
    max_vx_m_s: float = 0.25
    cruise_vx_m_s: float = 0.25  # what a behaviour walks at over distance (at most max_vx_m_s)
    max_vy_m_s: float = 0.08
    max_vyaw_rad_s: float = 0.8
    accel_m_s2: float = 0.3
    accel_yaw_rad_s2: float = 1.5
    arm_swing_rad: float = 0.3  # shoulder pitch per m/s of forward speed
    gyro_pitch_gain: float = 0.0  # rad per rad/s, on hip/ankle pitch
    gyro_roll_gain: float = 0.0  # rad per rad/s, on hip/ankle roll
    hip_roll_comp_rad: float = 0.0  # extra outward hip roll of the support leg (hip sag)
    tilt_pitch_ankle_gain: float = 0.0  # ankle pitch per rad of torso pitch error
    tilt_pitch_hip_gain: float = 0.0  # hip pitch per rad of torso pitch error
    tilt_roll_ankle_gain: float = 0.0  # ankle roll per rad of torso roll error
    tilt_roll_hip_gain: float = 0.0  # hip roll per rad of torso roll error
    # distance walked per commanded distance (x, y), measured: the servos' lag and slip
    stride_efficiency_x: float = 1.0
    stride_efficiency_y: float = 1.0
    turn_stride_loss: float = 0.0  # fraction of the stride lost per rad/s of turning, measured


class WalkEngine:
    """Turns a velocity command into motor targets, one control tick at a time.

    Example::

        engine = WalkEngine(model="kid-default")
        targets = engine.step(0.008, 0.15, 0.0, 0.0)  # {motor name: target rad}
    """

    def __init__(self, *, model: str = "kid-default", params: WalkParams | None = None) -> None:
        self.kin: RobotKinematics = kinematics(model)
        self.params = params or default_walk_params(model)
        self._phase = 0.0
        self._gait = 0.0  # 0 standing .. 1 full gait amplitude
        self._v = (0.0, 0.0, 0.0)
        self._filter = AttitudeFilter()

    @property
    def velocity(self) -> Vec3:
        """Velocity the gait is currently producing (vx m/s, vy m/s, vyaw rad/s): the smoothed
        command times the measured stride efficiency (less while turning), for odometry."""
        vx, vy, vyaw = self._v
        p = self.params
        turning = max(1.0 - p.turn_stride_loss * abs(vyaw), 0.5)
        return (vx * p.stride_efficiency_x * turning, vy * p.stride_efficiency_y * turning, vyaw)

    @property
    def walking(self) -> bool:
        return self._gait > 0.0

    def reset(self) -> None:
        self._phase, self._gait, self._v = 0.0, 0.0, (0.0, 0.0, 0.0)
        self._filter.reset()

    def step(
        self,
        dt_s: float,
        vx_m_s: float,
        vy_m_s: float,
        vyaw_rad_s: float,
        *,
        accel: Vec3 | None = None,
        gyro: Vec3 | None = None,
    ) -> dict[str, float]:
        """Advance the gait by ``dt_s`` and return the motor targets for that instant.

        With ``accel`` (m/s^2) and ``gyro`` (rad/s) from the torso IMU, the gait corrects the
        torso attitude (ankle and hip feedback); without them it runs open loop.
        """
        p = self.params
        tilt: tuple[float, float] | None = None
        if accel is not None and gyro is not None:
            attitude = self._filter.update(dt_s, accel, gyro)
            tilt = (attitude.roll_rad, attitude.pitch_rad)
        target = (
            _clip(vx_m_s, p.max_vx_m_s),
            _clip(vy_m_s, p.max_vy_m_s),
            _clip(vyaw_rad_s, p.max_vyaw_rad_s),
        )
        want_walk = any(abs(v) > 1e-4 for v in target)
        self._v = (
            _approach(self._v[0], target[0], p.accel_m_s2 * dt_s),
            _approach(self._v[1], target[1], p.accel_m_s2 * dt_s),
            _approach(self._v[2], target[2], p.accel_yaw_rad_s2 * dt_s),
        )
        ramp = dt_s / (0.5 * p.period_s)
        moving = any(abs(v) > 1e-3 for v in self._v)
        self._gait = _approach(self._gait, 1.0 if (want_walk or moving) else 0.0, ramp)
        if self._gait > 0.0:
            self._phase = (self._phase + dt_s / p.period_s) % 1.0
        else:
            self._phase = 0.0
        return self.pose_at(self._phase, gyro=gyro, tilt=tilt)

    def pose_at(
        self,
        phase: float,
        *,
        gyro: Vec3 | None = None,
        tilt: tuple[float, float] | None = None,
    ) -> dict[str, float]:
        """Motor targets at a gait ``phase`` in [0, 1) with the current velocity and amplitude."""
        p, leg = self.params, self.kin.leg
        vx, vy, vyaw = self._v
        lean = p.torso_pitch_rad + p.walk_lean_rad * self._gait
        sway = self._gait * p.sway_m * math.sin(2.0 * math.pi * (phase + p.sway_phase_lead))
        canonical: dict[str, dict[str, float]] = {}
        lifts = {
            side: _foot_profile((phase - offset) % 1.0, p.double_support_ratio)[1]
            for side, offset in (("left", 0.0), ("right", 0.5))
        }
        for side, sign, offset in (("left", 1.0, 0.0), ("right", -1.0, 0.5)):
            u = (phase - offset) % 1.0
            travel, lift = _foot_profile(u, p.double_support_ratio)
            other_lift = lifts["right" if side == "left" else "left"]
            half_cycle = p.period_s * (1.0 - _swing_fraction(p.double_support_ratio)) / 2.0
            target = FootTarget(
                p.foot_x_offset_m + vx * half_cycle * travel,
                sign * p.foot_y_offset_m + vy * half_cycle * travel + sway,
                -p.hip_height_m + self._gait * p.step_height_m * lift,
                vyaw * half_cycle * travel,
            )
            angles = leg_ik(leg, target)
            angles["hip_pitch"] -= lean
            angles["hip_roll"] += sign * p.hip_roll_comp_rad * other_lift * self._gait
            if tilt is not None:  # balance feedback while stepping only
                roll_err = tilt[0] * self._gait
                pitch_err = (tilt[1] - lean) * self._gait
                angles["ankle_pitch"] += p.tilt_pitch_ankle_gain * pitch_err
                angles["hip_pitch"] += p.tilt_pitch_hip_gain * pitch_err
                angles["ankle_roll"] += p.tilt_roll_ankle_gain * roll_err
                angles["hip_roll"] += p.tilt_roll_hip_gain * roll_err
            if gyro is not None:
                angles["hip_pitch"] += p.gyro_pitch_gain * gyro[1]
                angles["ankle_pitch"] -= p.gyro_pitch_gain * gyro[1]
                angles["hip_roll"] -= p.gyro_roll_gain * gyro[0]
                angles["ankle_roll"] += p.gyro_roll_gain * gyro[0]
            canonical[side] = angles
        swing = p.arm_swing_rad * vx * math.sin(2.0 * math.pi * phase) * self._gait
        targets = self.kin.left_leg.to_motor(canonical["left"])
        targets.update(self.kin.right_leg.to_motor(canonical["right"]))
        targets.update(self.kin.arm_targets(left_pitch=swing, right_pitch=-swing))
        targets.update(self.kin.head_targets(0.0, 0.0))
        return self.kin.clamp(targets)


def default_walk_params(model: str) -> WalkParams:
    kin = kinematics(model)
    return replace(WalkParams(), **kin.walk_overrides)


def _swing_fraction(double_support_ratio: float) -> float:
    """Fraction of a full cycle during which one foot is in the air."""
    return 0.5 * (1.0 - double_support_ratio)


def _foot_profile(u: float, double_support_ratio: float) -> tuple[float, float]:
    """(travel in [-1, 1], lift in [0, 1]) of a foot at its own cycle position ``u``.

    The foot swings in ``[start, end]`` of the first half of its cycle (travel -1 -> +1 with a
    cosine ease, lift a half sine) and is on the ground the rest of the cycle, sliding from +1
    back to -1 at constant speed.
    """
    swing = _swing_fraction(double_support_ratio)
    start = 0.25 * double_support_ratio
    end = start + swing
    if start <= u < end:
        s = (u - start) / swing
        return -math.cos(math.pi * s), math.sin(math.pi * s)
    stance = 1.0 - swing
    t = ((u - end) % 1.0) / stance
    return 1.0 - 2.0 * t, 0.0


def _approach(value: float, target: float, max_delta: float) -> float:
    if value < target:
        return min(value + max_delta, target)
    return max(value - max_delta, target)


def _clip(value: float, limit: float) -> float:
    return min(max(value, -limit), limit)
