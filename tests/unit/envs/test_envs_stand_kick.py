"""hlvs/StandKick-v0's shaped reward (approach, touch, progress, standing still, falls), its
curriculum setting and its settings shared with the MJX vector."""

from __future__ import annotations

import inspect
from typing import Any

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

import envs  # noqa: F401  (registers the ids)
from envs import EnvConfigError
from envs.frame import BALL_POS, TOE_R
from envs.stand_kick import (
    BALL_AHEAD_M,
    STILL_PENALTY,
    TOUCH_BONUS,
    StandKickConfig,
    StandKickEnv,
    stand_kick_reward,
)
from simulator.world import MOTOR_NAMES

HIP, KNEE = MOTOR_NAMES.index("LegUpperR"), MOTOR_NAMES.index("LegLowerR")


def _make(**options: Any) -> StandKickEnv:
    env = gym.make("hlvs/StandKick-v0", **options).unwrapped
    assert isinstance(env, StandKickEnv)
    return env


def _kick(env: StandKickEnv, seed: int) -> tuple[list[float], list[dict[str, Any]], dict[str, Any]]:
    """A scripted right-foot kick: knee up (5 steps), then swing the leg through (6 steps)."""
    _, first = env.reset(seed=seed)
    rewards: list[float] = []
    infos: list[dict[str, Any]] = []
    for k in range(env.max_steps):
        action = env.stance.copy()
        if k < 5:
            action[HIP] += 0.3
            action[KNEE] += 0.6
        elif k < 11:
            action[HIP] += 0.9
            action[KNEE] -= 0.8
        _, reward, terminated, truncated, info = env.step(action.astype(np.float32))
        rewards.append(float(reward))
        infos.append(info)
        if terminated or truncated:
            break
    return rewards, infos, first


def test_checker_passes() -> None:
    env = gym.make("hlvs/StandKick-v0")
    try:
        check_env(env.unwrapped, skip_render_check=True)
    finally:
        env.close()


def test_standing_still_costs_and_never_touches() -> None:
    env = _make()
    try:
        _, info = env.reset(seed=2)
        # the right toe is in front of the right foot, a few centimetres from the ball
        assert env.frame is not None
        toe, ball = env.frame.truth[TOE_R], env.frame.truth[BALL_POS]
        assert 0.005 < info["toe_to_ball_m"] < 0.06
        assert np.hypot(*(toe - ball)[:2]) < 0.15
        total, steps = 0.0, 0
        done = False
        while not done:
            _, reward, terminated, truncated, info = env.step(env.stance.astype(np.float32))
            total += float(reward)
            steps += 1
            done = terminated or truncated
        assert not info["touched"] and info["kick_distance_m"] < 0.01
        assert total == pytest.approx(-STILL_PENALTY * steps, abs=0.02)
    finally:
        env.close()


def test_a_kick_earns_the_approach_the_touch_and_the_progress() -> None:
    env = _make()
    try:
        rewards, infos, first = _kick(env, seed=1)
        touch = next(i for i, info in enumerate(infos) if info["touched"])
        gap_before = infos[touch - 1]["toe_to_ball_m"] if touch else first["toe_to_ball_m"]
        # the touch step pays the bonus on top of the toe's approach and the ball's progress
        assert rewards[touch] > TOUCH_BONUS
        assert gap_before > 0.0 and not infos[touch - 1]["touched"]
        assert all(info["touched"] for info in infos[touch:])
        last = infos[-1]
        assert not last["fallen"] and last["kick_distance_m"] > 0.5
        assert sum(rewards) > 2.0
        # with the shaping off the return is the plain 2 x progress of earlier versions
        plain = _make(approach_weight=0.0, touch_bonus=0.0, still_penalty=0.0)
        try:
            flat, flat_infos, first_plain = _kick(plain, seed=1)
            progress = first_plain["ball_to_goal_m"] - flat_infos[-1]["ball_to_goal_m"]
            assert sum(flat) == pytest.approx(2.0 * progress, abs=1e-6)
        finally:
            plain.close()
    finally:
        env.close()


def test_the_curriculum_brings_the_ball_nearer_the_toe() -> None:
    env = _make(ball_noise_m=0.0)
    try:
        _, far = env.reset(seed=4)
        env.ball_closer_m = 0.02  # as a trainer sets it between episodes
        _, near = env.reset(seed=4)
        assert far["toe_to_ball_m"] - near["toe_to_ball_m"] == pytest.approx(0.02, abs=0.006)
        assert (far["ball_closer_m"], near["ball_closer_m"]) == (0.0, 0.02)
        env.ball_closer_m = 0.2
        with pytest.raises(EnvConfigError) as caught:
            env.reset(seed=4)
        assert caught.value.field == "ball_closer_m"
    finally:
        env.close()


def test_reward_formula_on_arrays_as_on_floats() -> None:
    config = StandKickConfig()
    args: dict[str, Any] = {
        "progress": np.array([0.0, 0.1]),
        "gap_before": np.array([0.03, 0.01]),
        "gap_after": np.array([0.02, 0.0]),
        "touched_before": np.array([0.0, 0.0]),
        "touched": np.array([0.0, 1.0]),
        "fallen": np.array([0.0, 0.0]),
        "fall_penalty": 3.0,
    }
    batched = stand_kick_reward(config, **args)
    one = [stand_kick_reward(config, **{k: (v if np.isscalar(v) else float(v[i]))
                                        for k, v in args.items()}) for i in range(2)]  # fmt: skip
    np.testing.assert_allclose(batched, one)
    assert one[0] == pytest.approx(0.01 - STILL_PENALTY)
    assert one[1] == pytest.approx(0.2 + 0.01 + TOUCH_BONUS)


def test_settings_are_checked_and_shared_with_the_mjx_vector() -> None:
    with pytest.raises(EnvConfigError) as caught:
        gym.make("hlvs/StandKick-v0", fall_penalti=1.0)
    assert caught.value.field == "setting" and caught.value.value == "fall_penalti"
    assert caught.value.suggestion == "fall_penalty"
    with pytest.raises(EnvConfigError) as noise:
        StandKickConfig(ball_noise_m=0.5)
    assert noise.value.field == "ball_noise_m"
    with pytest.raises(EnvConfigError) as negative:
        StandKickConfig(touch_bonus=-1.0)
    assert negative.value.field == "touch_bonus"
    assert BALL_AHEAD_M > 0.1
    # one definition of the settings: neither class repeats StandKickConfig's fields
    from envs.mjx_vector import MjxStandKickVector

    settings = {f for f in StandKickConfig.__dataclass_fields__}
    for cls in (StandKickEnv, MjxStandKickVector):
        own = set(inspect.signature(cls.__init__).parameters)
        assert not own & settings, (cls.__name__, own & settings)
    with pytest.raises(EnvConfigError) as mjx_bad:
        MjxStandKickVector(2, ball_noise_m=0.5)  # checked before the world is built
    assert mjx_bad.value.field == "ball_noise_m"
    with pytest.raises(EnvConfigError) as mjx_adult:
        MjxStandKickVector(2, robot_class="adult")  # its world is the kid pitch's
    assert mjx_adult.value.field == "robot_class"


def test_the_policies_learn_with_the_servo_gains_the_robot_plays_them_with() -> None:
    """The environment never sends MotorPID: its robot has the simulator's default gains, which
    a robot playing the policy asks for (``robot.learned.LEARNT_SERVO_PID``)."""
    from robot.learned import LEARNT_SERVO_PID

    env = _make()
    env.reset(seed=3)
    env.step(env.action_space.sample())
    world = env.session.world
    assert world is not None
    assert set(world.motors.p.tolist()) == {LEARNT_SERVO_PID[0]}
    assert LEARNT_SERVO_PID == (10.0, 0.0, 0.0)
    env.close()


def test_the_adult_class_stands_its_robot_behind_the_adult_ball() -> None:
    """``robot_class="adult"``: adult-default eased into its stance on the adult pitch, the
    adult ball at its right toe, the observation laid out as the kid's (the same 20 motors)."""
    from contracts import field_for
    from robot.learned import kick_ball_offset
    from simulator.world.ball import BALL_BODY, BALL_GEOM

    adult = field_for("adult")
    with pytest.raises(EnvConfigError) as caught:
        StandKickConfig(robot_class="teen")
    assert caught.value.field == "robot_class"
    with pytest.raises(EnvConfigError) as unknown:
        StandKickConfig(robot_class="adult", model="giant-default")
    assert unknown.value.field == "model"
    env = _make(robot_class="adult", ball_noise_m=0.0)
    try:
        assert env.config.model == "adult-default"
        assert env.ball_spot == kick_ball_offset("adult-default")
        kid = _make()
        try:
            assert kid.observation_space == env.observation_space  # the kid's layout
            assert kid.ball_spot[0] < env.ball_spot[0]  # (the stances: the same angles, scaled)
        finally:
            kid.close()
        check_env(env, skip_render_check=True)
        obs, info = env.reset(seed=3)
        world = env.session.world  # type: ignore[attr-defined]
        assert world is not None
        model = world.model
        assert model.geom(BALL_GEOM).size[0] == pytest.approx(adult.ball_radius_m)
        assert model.body(BALL_BODY).mass[0] == pytest.approx(adult.ball_mass_kg)
        assert env.goal_xy[0] == adult.half_length_m
        ball = env.frame.truth[BALL_POS]  # type: ignore[union-attr]
        assert ball[2] == pytest.approx(adult.ball_radius_m, abs=0.02)  # resting on the grass
        assert 0.0 < info["toe_to_ball_m"] < 0.06 and not info["fallen"]  # at the toe, upright
        for _ in range(env.max_steps):  # standing in the stance: upright, the ball untouched
            obs, reward, terminated, truncated, info = env.step(env.stance.astype(np.float32))
            assert obs["joints"].shape == (len(MOTOR_NAMES),)
            if terminated or truncated:
                break
        assert truncated and not info["fallen"] and not info["touched"]
        rewards, infos, _ = _kick(env, seed=5)  # the kid's scripted kick moves the adult ball
        assert max(i["max_ball_speed_m_s"] for i in infos) > 0.1
    finally:
        env.close()
