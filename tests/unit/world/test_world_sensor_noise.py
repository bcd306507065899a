"""Sensor models: measured noise, bias, drift, saturation, quantisation and dead band of the
readings over 10,000 samples are the configured figures (within 10 %), seeded, and the true
state stays untouched.

The world stands still (no physics steps): :meth:`SensorNoise.update` draws a new reading of
the same true values each time, as it does after every basic step.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np
import pytest

from simulator.world import World
from simulator.world.sensor_noise import ImuAxisModel, SensorModel, SensorNoise

from .conftest import RED_1, eight_robots

SAMPLES = 10_000
QUIET = ImuAxisModel(white_std=0.0, bias_std=0.0, bias_walk_per_sqrt_s=0.0, saturation=1e9)


def _world(model: SensorModel, *, seed: int = 11, robots: int = 1) -> World:
    return World.create(
        field_class="kid", robots=eight_robots()[:robots], seed=seed, sensor_model=model
    )


def _noise(world: World) -> SensorNoise:
    assert world.sensor_noise is not None
    return world.sensor_noise


def _samples(world: World, read: Callable[[], float | list[float]]) -> np.ndarray:
    noise = _noise(world)
    out = []
    for _ in range(SAMPLES):
        noise.update()
        out.append(read())
    return np.asarray(out, dtype=np.float64)


def _true_gyro(world: World) -> np.ndarray:
    adr = world.index.by_id[RED_1].gyro
    return np.array(world.data.sensordata[adr : adr + 3])


def test_gyro_white_noise_and_bias_as_configured() -> None:
    gyro = ImuAxisModel(white_std=0.01, bias_std=0.02, bias_walk_per_sqrt_s=0.0, saturation=30)
    world = _world(SensorModel(gyro=gyro))
    bias = _noise(world).imu_bias[:3].copy()
    readings = _samples(world, lambda: list(world.read_gyro(RED_1)))
    error = readings - _true_gyro(world)
    assert error.std(axis=0) == pytest.approx([0.01] * 3, rel=0.1)
    # the mean error is this robot's constant bias (its std of the mean: 0.01 / 100)
    assert error.mean(axis=0) == pytest.approx(bias, abs=3 * 0.01 / math.sqrt(SAMPLES))
    assert np.abs(bias).max() > 0.0


def test_imu_biases_are_drawn_with_the_configured_spread() -> None:
    accel = ImuAxisModel(white_std=0.0, bias_std=0.05, bias_walk_per_sqrt_s=0.0, saturation=40)
    model = SensorModel(gyro=QUIET, accelerometer=accel)
    biases = []
    world = _world(model, robots=8)
    noise = _noise(world)
    while len(biases) < SAMPLES:  # 24 accelerometer axes per construction, new seed each time
        fresh = SensorNoise(
            model=model, flat=world._sensor_span, index=world.index,
            encoder_resolution_rad=noise._resolution, seed=len(biases), step_s=0.008,
        )  # fmt: skip
        biases.extend(fresh.imu_bias[24:].tolist())
    assert np.std(biases) == pytest.approx(0.05, rel=0.1)
    assert abs(float(np.mean(biases))) < 0.1 * 0.05


def test_bias_drift_is_a_random_walk_of_the_configured_rate() -> None:
    gyro = ImuAxisModel(white_std=0.0, bias_std=0.0, bias_walk_per_sqrt_s=0.01, saturation=30)
    world = _world(SensorModel(gyro=gyro))
    readings = _samples(world, lambda: world.read_gyro(RED_1)[0])
    steps = np.diff(readings)
    assert steps.std() == pytest.approx(0.01 * math.sqrt(0.008), rel=0.1)
    assert abs(steps.mean()) < 0.1 * steps.std()


def test_accelerometer_noise_and_saturation() -> None:
    accel = ImuAxisModel(white_std=0.05, bias_std=0.0, bias_walk_per_sqrt_s=0.0, saturation=39.24)
    world = _world(SensorModel(gyro=QUIET, accelerometer=accel))
    adr = world.index.by_id[RED_1].accelerometer
    world.data.sensordata[adr : adr + 3] = (0.5, -80.0, 9.81)  # y beyond the range
    readings = _samples(world, lambda: list(world.read_accelerometer(RED_1)))
    assert readings[:, 0].std() == pytest.approx(0.05, rel=0.1)
    assert readings[:, 0].mean() == pytest.approx(0.5, abs=0.005)
    assert np.all(readings[:, 1] == -39.24)


def test_joint_positions_are_quantised_encoder_readings() -> None:
    world = _world(SensorModel())
    slot = world.index.by_id[RED_1].motor_slot["Head"]
    resolution = world.index.by_id[RED_1].model.motors[slot].encoder_resolution_rad
    assert resolution == pytest.approx(2 * math.pi / 4096, rel=1e-6)  # the catalogue's 4096 counts
    qpos = int(world.index.by_id[RED_1].motor_qpos[slot])
    rng = np.random.default_rng(0)
    noise = _noise(world)
    errors, counts = [], []
    for _ in range(SAMPLES):
        true = float(rng.uniform(-1.0, 1.0))
        world.data.qpos[qpos] = true
        noise.update()
        reading = world.read_position(RED_1, "HeadS")
        counts.append(reading / resolution)
        errors.append(reading - true)
    counts_array = np.asarray(counts)
    assert np.abs(counts_array - np.rint(counts_array)).max() < 1e-6  # whole encoder counts
    # half a count of noise, then rounding: std sqrt(0.5^2 + 1/12) counts
    expected = math.sqrt(0.25 + 1 / 12) * resolution
    assert np.std(errors) == pytest.approx(expected, rel=0.1)
    assert abs(float(np.mean(errors))) < 0.1 * resolution


def test_joint_resolution_comes_from_the_motor() -> None:
    world = _world(SensorModel())
    motors = world.index.by_id[RED_1].model.motors
    assert all(m.encoder_resolution_rad == pytest.approx(0.001534, abs=1e-6) for m in motors)
    assert _noise(world)._resolution.tolist() == [m.encoder_resolution_rad for m in motors]


def test_foot_pressure_noise_and_dead_band() -> None:
    world = _world(SensorModel(force_std_n=0.2, force_dead_band_n=0.5))
    forces = world.index.by_id[RED_1].forces
    world.data.sensordata[forces["llb"]] = 5.0
    world.data.sensordata[forces["llf"]] = 0.3  # inside the dead band: reads 0 mostly
    world.data.sensordata[forces["lrf"]] = 0.0
    readings = _samples(
        world, lambda: [world.read_force(RED_1, n) for n in ("llb", "llf", "lrf")]
    )
    assert readings[:, 0].std() == pytest.approx(0.2, rel=0.1)
    assert readings[:, 0].mean() == pytest.approx(5.0, abs=0.01)
    # P(0.3 + N(0, 0.2) < 0.5) = Phi(1) = 0.841
    assert float(np.mean(readings[:, 1] == 0.0)) == pytest.approx(0.841, rel=0.1)
    assert readings[:, 1].min() == 0.0 and np.all(readings[:, 1][readings[:, 1] > 0] >= 0.5)
    # an unloaded sensor reads 0 but when the noise passes the dead band: P = 1 - Phi(2.5)
    assert float(np.mean(readings[:, 2] > 0.0)) == pytest.approx(0.0062, abs=0.003)


def test_same_seed_same_readings_and_the_truth_untouched() -> None:
    names = ["Gyro", "Accelerometer", "HeadS", "llb"]

    def run(model: SensorModel, seed: int) -> tuple[np.ndarray, World]:
        world = _world(model, seed=seed, robots=2)
        out = []
        for _ in range(20):
            world.step()
            out.append(world.read_sensors(RED_1, names))
        return np.array(out), world

    a, noisy = run(SensorModel(), 3)
    b, _ = run(SensorModel(), 3)
    c, _ = run(SensorModel(), 4)
    assert np.array_equal(a, b) and not np.array_equal(a, c)
    exact, ideal = run(SensorModel.ideal(), 3)
    assert not np.array_equal(a, exact)
    # noise never feeds back into the physics, and what the referee, the replay and telemetry
    # read (the snapshot) is the true state: the noisy world's equals the ideal world's
    assert np.array_equal(ideal.data.qpos, noisy.data.qpos)
    assert noisy.snapshot() == ideal.snapshot()
    gyro = ideal.index.by_id[RED_1].gyro
    assert ideal.read_gyro(RED_1) == tuple(ideal.data.sensordata[gyro : gyro + 3])


def test_every_read_path_gives_the_same_noisy_reading() -> None:
    world = _world(SensorModel(), robots=2)
    for _ in range(5):
        world.step()
    names = ["HeadS", "Gyro", "Accelerometer", "rrb"]
    flat = world.read_sensors(RED_1, names)
    gather = world.sensor_gatherer(world.sensor_sources(RED_1, names))()
    single = [
        world.read_position(RED_1, "HeadS"), *world.read_gyro(RED_1),
        *world.read_accelerometer(RED_1), world.read_force(RED_1, "rrb"),
    ]  # fmt: skip
    assert flat.tolist() == gather.tolist() == single
    assert world.read_positions(RED_1)["HeadS"] == single[0]
    slot = world.index.by_id[RED_1].motor_slot["Head"]
    assert world.read_position_array(RED_1)[slot] == single[0]
    true_head = float(world.data.qpos[world.index.by_id[RED_1].motor_qpos[slot]])
    assert single[0] != true_head
