"""Domain randomisation: the look and the sensor models of an episode's world.

A session's ``look`` is ``"fixed"`` (every episode in the look of ``texture_seed``) or
``"random"`` (each episode draws its texture seed: turf, ball, background and light change);
its ``sensors`` are ``"ideal"`` (exact readings and images, the default), ``"league"`` (the
figures a match plays with: :mod:`simulator.world.sensor_noise`,
:mod:`simulator.world.camera_model`) or ``"random"`` (each episode scales every noise figure by
its own factor in 0.5..2, draws the camera's exposure gain in 0.75..1.25 and its pixel noise in
0..4 grey levels, and turns motion blur on in half the episodes). Every draw comes from the
episode's seed, so a seeded episode repeats exactly.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from simulator.world import CameraModel, ImuAxisModel, SensorModel

NOISE_SCALE = (0.5, 2.0)


@dataclass(frozen=True, slots=True)
class EpisodeWorld:
    """What an episode's world is built with."""

    texture_seed: int
    sensor_model: SensorModel
    camera_model: CameraModel


def _scaled(axis: ImuAxisModel, rng: np.random.Generator) -> ImuAxisModel:
    low, high = NOISE_SCALE
    return replace(
        axis,
        white_std=axis.white_std * float(rng.uniform(low, high)),
        bias_std=axis.bias_std * float(rng.uniform(low, high)),
        bias_walk_per_sqrt_s=axis.bias_walk_per_sqrt_s * float(rng.uniform(low, high)),
    )


def episode_world(*, look: str, texture_seed: int, sensors: str, seed: int) -> EpisodeWorld:
    """The look and sensor models of the episode of ``seed`` (see the module docstring)."""
    rng = np.random.default_rng([seed, 0xD0A1])
    episode_texture_seed = int(rng.integers(0, 2**31)) if look == "random" else texture_seed
    if sensors == "ideal":
        return EpisodeWorld(episode_texture_seed, SensorModel.ideal(), CameraModel.ideal())
    if sensors == "league":
        return EpisodeWorld(episode_texture_seed, SensorModel(), CameraModel.league(seed))
    base = SensorModel()
    low, high = NOISE_SCALE
    sensor_model = replace(
        base,
        gyro=_scaled(base.gyro, rng),
        accelerometer=_scaled(base.accelerometer, rng),
        encoder_noise_counts=base.encoder_noise_counts * float(rng.uniform(low, high)),
        force_std_n=base.force_std_n * float(rng.uniform(low, high)),
        force_dead_band_n=base.force_dead_band_n * float(rng.uniform(low, high)),
    )
    camera_model = CameraModel(
        seed=seed,
        exposure_gain=float(rng.uniform(0.75, 1.25)),
        noise_std=float(rng.uniform(0.0, 4.0)),
        motion_blur=bool(rng.uniform() < 0.5),
    )
    return EpisodeWorld(episode_texture_seed, sensor_model, camera_model)
