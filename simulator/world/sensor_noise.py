"""Sensor models: what the robot API reads instead of MuJoCo's exact values.

Figures of common parts (defaults of :class:`SensorModel`):

- **Gyro and accelerometer** (an MPU-6500-class IMU, as on kid-size robots, after the usual
  start-up calibration): white noise per sample (gyro 0.002 rad/s, accelerometer 0.03 m/s^2,
  from the noise densities 0.01 deg/s/sqrt(Hz) and 300 ug/sqrt(Hz) over the 62 Hz band of a
  125 Hz reading), a constant bias per axis drawn once per robot (std 0.005 rad/s and
  0.05 m/s^2), a bias drift (random walk, 0.0005 rad/s and 0.002 m/s^2 per sqrt(s)) and
  saturation at the range of the league's Darwin-OP lookup tables (+-27.925 rad/s,
  +-39.24 m/s^2).
- **Joint position sensors**: the servo's magnetic encoder: Gaussian noise of half a count,
  then quantised to the encoder's resolution (per joint, ``encoder_resolution_rad`` of the
  robot model's motor; 2 pi / 4096 rad for the 4096-count encoders of the Dynamixel servos).
- **Foot pressure sensors**: Gaussian noise of 0.1 N, a dead band (a reading below 0.5 N
  reads 0) and never negative.

Every random draw comes from a stream seeded by the match seed, and the noise of every
sensor is drawn once per basic step whether a robot reads it or not: the same seed gives the
same readings, however the robots' requests are timed. Measurements carry the time stamps of
the league's API (the step's simulated ``time`` in ms and ``real_time``), set by the API.

:class:`SensorNoise` keeps a noisy copy of the span of ``qpos`` and ``sensordata`` that the
world's sensor reads take their values from (:class:`simulator.world.flat.FlatData`); the
snapshot (referee, replay, telemetry) reads the true values. ``SensorModel.ideal()``
turns all of it off: the reads then see MuJoCo's values.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
import numpy.typing as npt

if TYPE_CHECKING:
    from simulator.world.flat import FlatData
    from simulator.world.indices import WorldIndex

ENCODER_RESOLUTION_RAD = 2.0 * math.pi / 4096.0  # ~0.0015 rad, 4096 counts per revolution
BLOCK_STEPS = 125  # steps of noise drawn at once (one simulated second)


@dataclass(frozen=True, slots=True, kw_only=True)
class ImuAxisModel:
    """Noise of one kind of inertial sensor, per axis."""

    white_std: float  # per sample
    bias_std: float  # of the constant bias drawn per robot and axis
    bias_walk_per_sqrt_s: float  # std of the bias' random walk after one second
    saturation: float  # readings are clipped to +-saturation


@dataclass(frozen=True, slots=True, kw_only=True)
class SensorModel:
    """The sensor figures of a match; ``enabled`` False is the ideal mode."""

    enabled: bool = True
    gyro: ImuAxisModel = ImuAxisModel(
        white_std=0.002, bias_std=0.005, bias_walk_per_sqrt_s=0.0005, saturation=27.925
    )
    accelerometer: ImuAxisModel = ImuAxisModel(
        white_std=0.03, bias_std=0.05, bias_walk_per_sqrt_s=0.002, saturation=39.24
    )
    encoder_noise_counts: float = 0.5  # std of the encoder noise, in counts
    force_std_n: float = 0.1
    force_dead_band_n: float = 0.5

    @classmethod
    def ideal(cls) -> SensorModel:
        return cls(enabled=False)


class SensorNoise:
    """The noisy readings of every robot's sensors, updated once per basic step.

    ``values`` has the layout of ``flat.values``; only the sensors' entries are kept up to date
    (the rest is never read through it).
    """

    def __init__(
        self,
        *,
        model: SensorModel,
        flat: FlatData,
        index: WorldIndex,
        encoder_resolution_rad: npt.NDArray[np.float64],
        seed: int,
        step_s: float,
    ) -> None:
        self.model = model
        self._flat = flat
        self.values: npt.NDArray[np.float64] = np.array(flat.values, dtype=np.float64)
        q_src = np.concatenate([r.motor_qpos for r in index.robots] or [np.zeros(0, np.int64)])
        imu: list[int] = []  # every IMU's gyro, robot by robot, then every accelerometer
        for r in index.robots:
            for _accelerometer, gyro in r.imus:
                imu.extend(range(gyro, gyro + 3))
        ngyro = len(imu)
        for r in index.robots:
            for accelerometer, _gyro in r.imus:
                imu.extend(range(accelerometer, accelerometer + 3))
        forces = [adr for r in index.robots for adr in r.forces.values()]
        self._nq = len(q_src)
        self._ngyro = ngyro
        self._nimu = len(imu)
        self._index = np.concatenate(
            [
                flat.indices("qpos", q_src),
                flat.indices("sensordata", np.asarray(imu, dtype=np.int64)),
                flat.indices("sensordata", np.asarray(forces, dtype=np.int64)),
            ]
        ).astype(np.intp)
        if len(encoder_resolution_rad) != self._nq:
            raise ValueError(
                f"{len(encoder_resolution_rad)} encoder resolutions for {self._nq} joints"
            )
        self._resolution = np.asarray(encoder_resolution_rad, dtype=np.float64)
        self._inverse_resolution = 1.0 / self._resolution
        self.rng = np.random.default_rng([seed, 0x5E45])
        g, a = model.gyro, model.accelerometer
        n = len(self._index)
        nq, ngyro, nimu = self._nq, self._ngyro, self._nimu
        self._std = np.zeros(n)
        self._std[:nq] = model.encoder_noise_counts * self._resolution
        self._std[nq : nq + ngyro] = g.white_std
        self._std[nq + ngyro : nq + nimu] = a.white_std
        self._std[nq + nimu :] = model.force_std_n
        bias_std = np.zeros(nimu)
        bias_std[:ngyro], bias_std[ngyro:] = g.bias_std, a.bias_std
        self._walk = np.zeros(nimu)
        self._walk[:ngyro] = g.bias_walk_per_sqrt_s * math.sqrt(step_s)
        self._walk[ngyro:] = a.bias_walk_per_sqrt_s * math.sqrt(step_s)
        # one clip per step: joints unbounded, the IMU saturates, forces are never negative
        self._low = np.full(n, -np.inf)
        self._high = np.full(n, np.inf)
        self._low[nq + ngyro : nq + nimu] = -a.saturation
        self._high[nq + ngyro : nq + nimu] = a.saturation
        self._low[nq : nq + ngyro] = -g.saturation
        self._high[nq : nq + ngyro] = g.saturation
        self._low[nq + nimu :] = 0.0
        self._dead_band = model.force_dead_band_n
        self._bias_now = self.rng.normal(0.0, 1.0, nimu) * bias_std
        self._offsets: npt.NDArray[np.float64] = np.zeros((0, n))
        self._bias_rows: npt.NDArray[np.float64] = np.zeros((0, nimu))
        self._row = 0
        self.update()

    @property
    def imu_bias(self) -> npt.NDArray[np.float64]:
        """The biases of the last readings: gyro x y z of every robot's IMUs, then
        accelerometer."""
        row: npt.NDArray[np.float64] = self._bias_rows[self._row - 1]
        return row

    def _draw_block(self) -> None:
        """The noise of the next :data:`BLOCK_STEPS` steps in one draw: white noise plus the
        IMU biases' random walk from where the last block left it."""
        n, nq, nimu = len(self._index), self._nq, self._nimu
        draws = self.rng.standard_normal((BLOCK_STEPS, n + nimu))
        offsets = draws[:, :n] * self._std
        bias = np.cumsum(draws[:, n:] * self._walk, axis=0) + self._bias_now
        offsets[:, nq : nq + nimu] += bias
        self._bias_now = bias[-1].copy()
        self._offsets, self._bias_rows, self._row = offsets, bias, 0

    def update(self) -> None:
        """Draw this step's readings from the true values (after the physics step): a few numpy
        calls on about 35 values per robot (each call costs microseconds right after
        ``mj_step``: the noise itself is drawn a block of steps at a time)."""
        if self._row == len(self._offsets):
            self._draw_block()
        offsets = self._offsets[self._row]
        self._row += 1
        nq = self._nq
        v = self._flat.values.take(self._index)
        v += offsets
        q = v[:nq]
        np.multiply(q, self._inverse_resolution, out=q)
        np.rint(q, out=q)
        np.multiply(q, self._resolution, out=q)
        np.maximum(v, self._low, out=v)  # (``np.clip`` is the same through Python wrappers)
        np.minimum(v, self._high, out=v)
        f = v[nq + self._nimu :]
        f[f < self._dead_band] = 0.0
        self.values.put(self._index, v)
