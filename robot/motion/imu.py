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


class GyroBias:
    """The gyro's bias, learnt while the robot stands still.

    A real gyro reads a few thousandths of a radian per second when it does not turn (the
    league's IMU model draws a bias of 0.005 rad/s per axis and robot, which then drifts):
    integrated over the 30 s of READY that turns the believed heading by about 10 degrees, enough
    to send a shot from 3 m a metre wide of where the robot aims. Robots learn the bias when
    they know they are still, as real robots calibrate at start-up: the mean of the readings
    taken still, older ones forgotten over ``memory_s`` so that the bias' drift is followed.
    """

    def __init__(self, *, memory_s: float = 20.0, min_still_s: float = 0.3) -> None:
        self._memory_s = memory_s
        self._min_still_s = min_still_s
        self._sum = (0.0, 0.0, 0.0)
        self._weight = 0.0

    @property
    def bias(self) -> Vec3:
        """The learnt bias (zero until the robot was still for ``min_still_s``)."""
        if self._weight < self._min_still_s:
            return (0.0, 0.0, 0.0)
        sx, sy, sz = self._sum
        return (sx / self._weight, sy / self._weight, sz / self._weight)

    def learn(self, dt_s: float, gyro: Vec3) -> None:
        """One reading taken while the robot stood still."""
        keep = math.exp(-dt_s / self._memory_s)
        sx, sy, sz = self._sum
        gx, gy, gz = gyro
        self._sum = (keep * sx + dt_s * gx, keep * sy + dt_s * gy, keep * sz + dt_s * gz)
        self._weight = keep * self._weight + dt_s

    def corrected(self, gyro: Vec3) -> Vec3:
        bx, by, bz = self.bias
        return (gyro[0] - bx, gyro[1] - by, gyro[2] - bz)
