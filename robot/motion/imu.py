"""Torso attitude from the accelerometer and gyro: a complementary filter.

Frames follow the robot: x forward, y left, z up. ``roll`` is a right-hand rotation about x
(positive: left side up), ``pitch`` about y (positive: leaning forward). The accelerometer reads
the specific force (about +9.81 on z when upright and still), the gyro body rates in rad/s.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

Vec3 = tuple[float, float, float]
GRAVITY_M_S2 = 9.81


@dataclass(frozen=True, slots=True)
class Attitude:
    roll_rad: float
    pitch_rad: float

    @property
    def tilt_rad(self) -> float:
        """Angle between the torso's up axis and the vertical."""
        return math.acos(max(-1.0, min(1.0, math.cos(self.roll_rad) * math.cos(self.pitch_rad))))


def accel_attitude(accel: Vec3) -> Attitude:
    """Attitude from gravity alone (valid when the torso does not accelerate much)."""
    ax, ay, az = accel
    return Attitude(math.atan2(ay, az), math.atan2(-ax, math.hypot(ay, az)))


class AttitudeFilter:
    """Integrates the gyro and pulls towards the accelerometer's attitude with ``time_constant_s``.

    Readings whose magnitude is far from gravity (impacts, falls) are not used for correction.
    """

    def __init__(self, *, time_constant_s: float = 0.5, warm_up_s: float = 1.0) -> None:
        self._tau = time_constant_s
        self._warm_up_s = warm_up_s  # converge faster (time constant / 5) this long at start
        self._elapsed_s = 0.0
        self._attitude: Attitude | None = None

    @property
    def attitude(self) -> Attitude:
        return self._attitude or Attitude(0.0, 0.0)

    def reset(self) -> None:
        self._attitude = None
        self._elapsed_s = 0.0

    def update(self, dt_s: float, accel: Vec3, gyro: Vec3) -> Attitude:
        measured = accel_attitude(accel)
        norm = math.sqrt(sum(a * a for a in accel))
        trusted = abs(norm - GRAVITY_M_S2) < 0.3 * GRAVITY_M_S2
        if self._attitude is None:
            if not trusted:  # e.g. an all-zero first reading: wait for a sane one
                return self.attitude
            self._attitude = measured
            return measured
        roll = self._attitude.roll_rad + gyro[0] * dt_s
        pitch = self._attitude.pitch_rad + gyro[1] * dt_s
        self._elapsed_s += dt_s
        if trusted:
            tau = self._tau / 5.0 if self._elapsed_s < self._warm_up_s else self._tau
            weight = dt_s / (tau + dt_s)
            roll += weight * _wrap(measured.roll_rad - roll)
            pitch += weight * (measured.pitch_rad - pitch)
        self._attitude = Attitude(_wrap(roll), pitch)
        return self._attitude


def _wrap(angle: float) -> float:
    return (angle + math.pi) % (2.0 * math.pi) - math.pi
