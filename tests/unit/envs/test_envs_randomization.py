"""Domain randomisation: the look and the sensor noise of each episode come from its seed."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest

import envs  # noqa: F401  (registers the ids)
from envs import EnvConfigError
from envs.randomization import episode_world


def test_random_look_and_sensors_change_per_episode_and_repeat_per_seed() -> None:
    first = episode_world(look="random", texture_seed=0, sensors="random", seed=1)
    assert first == episode_world(look="random", texture_seed=0, sensors="random", seed=1)
    others = [
        episode_world(look="random", texture_seed=0, sensors="random", seed=s) for s in range(2, 8)
    ]
    assert len({e.texture_seed for e in [first, *others]}) == 7
    gyro_noise = {e.sensor_model.gyro.white_std for e in [first, *others]}
    assert len(gyro_noise) == 7 and all(0.001 <= g <= 0.004 for g in gyro_noise)
    assert len({e.camera_model.noise_std for e in [first, *others]}) == 7
    fixed = episode_world(look="fixed", texture_seed=5, sensors="ideal", seed=3)
    assert fixed.texture_seed == 5 and not fixed.sensor_model.enabled
    assert fixed.camera_model.is_ideal


def _gyro_readings(seed: int, **kwargs: object) -> np.ndarray:
    env = gym.make("hlvs/Kick-v0", **kwargs)
    try:
        env.reset(seed=seed)
        session = env.unwrapped.session
        world = session.world
        for _ in range(3):
            env.step(env.action_space.sample() * 0)
        return np.array(world.read_gyro(session.learner))
    finally:
        env.close()


def test_the_kick_env_reads_noisy_sensors_when_asked() -> None:
    noisy = _gyro_readings(4, sensors="random", look="random")
    assert np.array_equal(noisy, _gyro_readings(4, sensors="random", look="random"))
    ideal = _gyro_readings(4)
    assert not np.array_equal(noisy, ideal)


def test_unknown_modes_are_refused_with_the_choices() -> None:
    with pytest.raises(EnvConfigError, match="sensors"):
        gym.make("hlvs/Kick-v0", sensors="noisy")
    with pytest.raises(EnvConfigError, match="look"):
        gym.make("hlvs/Match-v0", look="pretty")
