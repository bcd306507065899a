"""The hlvs Gymnasium environments in-process: checker, seeding, rewards, trainer, errors."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

import envs
from envs import EnvConfigError, EnvStateError, TrainerError


@pytest.mark.parametrize(
    ("env_id", "kwargs"),
    [
        ("hlvs/Kick-v0", {}),
        ("hlvs/Kick-v0", {"perception": True, "perception_noise": 0.02}),
        ("hlvs/Match-v0", {"perception": True, "half_duration_s": 5.0, "minimum_play_s": 0.0}),
    ],
)
def test_gymnasium_checker_passes(env_id: str, kwargs: dict[str, object]) -> None:
    env = gym.make(env_id, **kwargs)
    try:
        check_env(env.unwrapped, skip_render_check=True)
    finally:
        env.close()


def _flat(obs: object) -> bytes:
    if isinstance(obs, dict):
        return b"".join(_flat(v) for _, v in sorted(obs.items()))
    return np.asarray(obs).tobytes()


def _rollout(env_id: str, seed: int, steps: int, **kwargs: object) -> list[tuple[object, ...]]:
    env = gym.make(env_id, **kwargs)
    rng = np.random.default_rng(seed)
    out: list[tuple[object, ...]] = []
    obs, info = env.reset(seed=seed)
    out.append((obs["joints"].tobytes(), info.get("sim_time_ms")))
    for _ in range(steps):
        action = rng.uniform(-0.1, 0.1, 20).astype(np.float32)
        obs, reward, terminated, truncated, info = env.step(action)
        out.append((_flat(obs), float(reward), terminated, truncated))
    env.close()
    return out


def test_seeded_episodes_repeat_and_differ_by_seed() -> None:
    first = _rollout("hlvs/Kick-v0", 7, 150, perception=True, perception_noise=0.05)
    again = _rollout("hlvs/Kick-v0", 7, 150, perception=True, perception_noise=0.05)
    other = _rollout("hlvs/Kick-v0", 8, 150, perception=True, perception_noise=0.05)
    assert first == again
    assert first != other


def test_match_seeded_runs_repeat() -> None:
    assert _rollout("hlvs/Match-v0", 3, 200, half_duration_s=5.0, minimum_play_s=0.0) == _rollout(
        "hlvs/Match-v0", 3, 200, half_duration_s=5.0, minimum_play_s=0.0
    )


def test_kick_reward_counts_ball_progress_and_goal() -> None:
    env = gym.make("hlvs/Kick-v0")
    env.reset(seed=1, options={"ball_x_m": 3.8, "ball_y_m": 0.0, "robot_pose": (3.0, 0, 0)})
    stand = np.zeros(20, np.float32)
    env.unwrapped.trainer.place_ball(4.0, 0.0, 3.0, 0.0)  # rolls into the goal
    total, info, terminated = 0.0, {}, False
    for _ in range(200):
        _, reward, terminated, truncated, info = env.step(stand)
        total += float(reward)
        if terminated or truncated:
            break
    env.close()
    assert terminated and info["goal"] and not info["fallen"]
    assert total > 10.0  # the goal bonus plus the ball's progress
    assert info["kick_distance_m"] > 0.5


def test_kick_falls_terminate_with_a_penalty() -> None:
    env = gym.make("hlvs/Kick-v0")
    env.reset(seed=2)
    limp_pose = np.array(env.action_space.high, dtype=np.float32)  # every joint at its limit
    rewards, info = [], {}
    for _ in range(500):
        _, reward, terminated, truncated, info = env.step(limp_pose)
        rewards.append(float(reward))
        if terminated or truncated:
            break
    env.close()
    assert info["fallen"] and terminated
    assert rewards[-1] < -0.5


def test_match_trainer_sets_state_places_ball_and_drops_it() -> None:
    env = gym.make("hlvs/Match-v0", half_duration_s=20.0)
    obs, info = env.reset(seed=4)
    assert info["game"]["state"] in ("INITIAL", "READY")
    trainer = env.unwrapped.trainer
    trainer.set_game_state("PLAYING")
    obs, *_, info = env.step(np.zeros(20, np.float32))
    assert info["game"]["state"] == "PLAYING" and obs["game"]["state"] == 3
    trainer.place_ball(1.0, -0.5)
    trainer.place_robot("blue", 2, 3.0, 2.0, 0.0)
    env.step(np.zeros(20, np.float32))
    frame = env.unwrapped.frame
    assert np.allclose(frame.truth[0:2], (1.0, -0.5), atol=0.02)
    trainer.drop_ball(0.5, 0.5)
    *_, info = env.step(np.zeros(20, np.float32))
    assert info["game"]["state"] == "READY" and not info["game"]["own_kickoff"]
    with pytest.raises(TrainerError) as caught:
        trainer.set_game_state("PLAYNG")
    assert "PLAYING" in str(caught.value)
    with pytest.raises(TrainerError):
        trainer.place_robot("blue", 9, 0.0, 0.0, 0.0)
    env.close()


def test_match_reward_follows_the_score() -> None:
    env = gym.make("hlvs/Match-v0", half_duration_s=30.0, stubs=())
    env.reset(seed=5)
    trainer = env.unwrapped.trainer
    trainer.set_game_state("PLAYING")
    for _ in range(200):  # wait until the ball may be scored (kick-off protection)
        env.step(np.zeros(20, np.float32))
    trainer.place_ball(4.2, 0.0, 3.0, 0.0)
    total, info = 0.0, {}
    for _ in range(150):
        _, reward, _, _, info = env.step(np.zeros(20, np.float32))
        total += float(reward)
    env.close()
    assert info["game"]["score_own"] == 1
    assert total > 0.9


def test_skill_env_has_no_game_state() -> None:
    env = gym.make("hlvs/Kick-v0")
    env.reset(seed=1)
    with pytest.raises(TrainerError) as caught:
        env.unwrapped.trainer.set_game_state("PLAYING")
    assert "no referee" in str(caught.value)
    env.close()


def test_misuse_is_caught_with_fields() -> None:
    env = gym.make("hlvs/Kick-v0", disable_env_checker=True).unwrapped
    with pytest.raises(EnvStateError):
        env.step(np.zeros(20, np.float32))
    env.reset(seed=1)
    with pytest.raises(EnvConfigError) as caught:
        env.step(np.zeros(7, np.float32))
    assert caught.value.field == "action"
    env.close()
    with pytest.raises(EnvConfigError) as bad:
        gym.make("hlvs/Kick-v0", field_class="kids")
    assert bad.value.field == "field_class" and bad.value.suggestion == "kid"
    assert set(envs.ENV_IDS) <= set(gym.registry)


def test_camera_observation_and_render() -> None:
    env = gym.make("hlvs/Kick-v0", camera=True, render_mode="rgb_array")
    obs, _ = env.reset(seed=1)
    assert obs["camera"].shape == (240, 320, 3) and obs["camera"].dtype == np.uint8
    assert env.observation_space.contains(obs)
    image = env.render()
    assert image is not None and image.shape == (240, 320, 3)
    green = image[:, :, 1].astype(int) - image[:, :, 0].astype(int)
    assert (green > 30).mean() > 0.2  # the robot looks at the turf
    env.close()


def test_in_process_vector_env() -> None:
    from envs.vector import make_vector

    vec = make_vector("hlvs/Kick-v0", remotes=None, num_envs=2)
    obs, _ = vec.reset(seed=3)
    assert obs["joints"].shape == (2, 20)
    obs, rewards, *_ = vec.step(np.zeros((2, 20), np.float32))
    assert rewards.shape == (2,) and not np.array_equal(obs["joints"][0], obs["joints"][1])
    vec.close()
