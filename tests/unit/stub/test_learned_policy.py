"""The learned-policy file, its numpy runner and the stub's use of it (robot.learned)."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from contracts.gamecontroller import GameState
from contracts.geometry import Pose
from robot.learned import (
    LEARNT_SERVO_PID,
    Policy,
    PolicyFileError,
    PolicyMotion,
    load_policy,
    save_policy,
)
from robot.learned.policy import KICK_BALL_AHEAD_M, kick_ball_offset
from robot.motion import SERVO_PID
from robot.stub import StubConfigError, parse_args
from robot.stub.behaviour import (
    KICK_OFF_SHORT_M,
    Field,
    GameInfo,
    Role,
    _kick_off_position,
    decide,
)
from robot.stub.controller import Sensors, StubController
from robot.stub.learned_kick import (
    HOLD_S,
    PLAY_S,
    PREPARE_S,
    RECOVER_S,
    RISEN_HOLD_S,
    SHOT_RANGE_M,
    SHOT_RANGE_MARGIN_M,
    LearnedKick,
    handover_s,
    in_shot_range,
)
from robot.stub.runner import _kick_policy

MOTORS = tuple(f"M{i}" for i in range(20))


def make_policy(seed: int = 0, *, period_ms: int = 32, duration_s: float = 0.2) -> Policy:
    rng = np.random.default_rng(seed)
    layers = ((rng.normal(0, 0.3, (27, 8)), rng.normal(0, 0.1, 8)),
              (rng.normal(0, 0.3, (8, 20)), rng.normal(0, 0.1, 20)))  # fmt: skip
    return Policy(
        skill="test-kick", motors=MOTORS, layers=layers, obs_scale=np.full(27, 0.5),
        stance=np.linspace(-0.2, 0.2, 20), action_scale=np.full(20, 0.4),
        low=np.full(20, -0.3), high=np.full(20, 0.3), control_period_ms=period_ms,
        duration_s=duration_s,
    )  # fmt: skip


def test_policy_file_round_trip_and_the_network(tmp_path: Path) -> None:
    policy = make_policy()
    save_policy(policy, tmp_path / "p.npz")
    loaded = load_policy(tmp_path / "p.npz")
    assert loaded.motors == MOTORS and loaded.skill == "test-kick"
    assert loaded.control_period_ms == 32 and loaded.duration_s == pytest.approx(0.2)
    obs = loaded.observation(dict(zip(MOTORS, np.linspace(0, 1, 20), strict=True)),
                             (0.0, 0.0, 9.8), (0.1, 0.0, 0.0), 0.5)  # fmt: skip
    assert obs.shape == (27,) and obs[-1] == 0.5 and obs[22] == pytest.approx(9.8)
    (w0, b0), (w1, b1) = policy.layers
    expected = np.tanh(np.tanh(obs * 0.5 @ w0 + b0) @ w1 + b1)
    np.testing.assert_allclose(loaded.mean_action(obs), expected)
    targets = loaded.act(obs)
    np.testing.assert_allclose(targets, np.clip(policy.stance + 0.4 * expected, -0.3, 0.3))
    assert np.all(targets <= 0.3) and np.all(targets >= -0.3)


def test_bad_policy_files_name_the_file_and_field(tmp_path: Path) -> None:
    with pytest.raises(PolicyFileError) as missing:
        load_policy(tmp_path / "none.npz")
    assert missing.value.field == "/" and "none.npz" in str(missing.value)
    np.savez(tmp_path / "other.npz", format=np.array("something-else"))
    with pytest.raises(PolicyFileError) as other:
        load_policy(tmp_path / "other.npz")
    assert other.value.field == "/format"
    good = make_policy()
    bad = Policy(**{**{f: getattr(good, f) for f in Policy.__dataclass_fields__},
                    "layers": ((np.zeros((26, 20)), np.zeros(20)),)})  # fmt: skip
    save_policy(bad, tmp_path / "shape.npz")
    with pytest.raises(PolicyFileError) as shape:
        load_policy(tmp_path / "shape.npz")
    assert shape.value.field == "/w0" and "27" in shape.value.expected


def test_policy_motion_decides_once_per_control_period_until_done() -> None:
    policy = make_policy(period_ms=32, duration_s=0.2)
    motion = PolicyMotion(policy)
    joints = dict.fromkeys(MOTORS, 0.0)
    seen_times: list[float] = []
    ticks = 0
    while not motion.done:
        motion.sense(joints, (0.0, 0.0, 9.8), (0.0, 0.0, 0.0))
        before = motion.decisions
        targets = motion.step(0.008)
        if motion.decisions > before:
            seen_times.append(round(motion.elapsed_s - 0.008, 3))
        ticks += 1
        assert set(targets) == set(MOTORS)
    assert ticks == 25  # 0.2 s of 8 ms ticks
    assert seen_times == [0.0, 0.032, 0.064, 0.096, 0.128, 0.16, 0.192]
    expected = policy.act(policy.observation(joints, (0.0, 0.0, 9.8), (0.0, 0.0, 0.0), 0.192))
    np.testing.assert_allclose([targets[m] for m in MOTORS], expected)


def test_stub_with_a_kick_policy_lines_up_for_the_right_foot(tmp_path: Path) -> None:
    save_policy(make_policy(), tmp_path / "kick.npz")
    options = parse_args(["striker", "--kick-policy", str(tmp_path / "kick.npz")])
    policy = _kick_policy(options)
    assert policy is not None and policy.skill == "test-kick"
    controller = StubController(role=Role.STRIKER, start_pose=Pose(x_m=0, y_m=0, yaw_rad=0),
                                kick_policy=policy)
    assert controller.field.kick_x_m == KICK_BALL_AHEAD_M
    assert controller.field.kick_feet == ("right",)
    # adult-default lines the ball up where hlvs/StandKick-v0 puts it for that model (near the
    # goal: its learned kick is a shot, test_the_adult_learned_kick_is_a_shot)
    adult = StubController(role=Role.STRIKER, start_pose=Pose(x_m=0, y_m=0, yaw_rad=0),
                           model="adult-default", field_class="adult", kick_policy=policy)
    adult.field = adult._kick_choice.update((6.0, 0.0))
    ahead, right = kick_ball_offset("adult-default")
    assert adult.field.kick_x_m == ahead > KICK_BALL_AHEAD_M
    assert adult.field.foot_y_m == pytest.approx(right)
    game = GameInfo(phase=GameState.PLAYING)
    # ball lined up in front of the LEFT foot: a plain stub kicks with the left foot, one with
    # a right-foot policy steps across instead
    field = Field(half_length_m=4.5, centre_circle_m=0.75, foot_y_m=0.075,
                  kick_x_m=KICK_BALL_AHEAD_M)
    ball = (KICK_BALL_AHEAD_M, 0.075)
    at = Pose(x_m=1.0, y_m=0.0, yaw_rad=0.0)
    plain = decide(role=Role.STRIKER, game=game, pose=at, ball=ball,
                   field=field, searching_s=0.0)  # fmt: skip
    assert plain.kick_foot == "left"
    right_only = decide(role=Role.STRIKER, game=game, pose=at, ball=ball,
                        field=controller.field, searching_s=0.0)  # fmt: skip
    assert right_only.kick_foot is None and right_only.walk[1] > 0  # side-steps to its left


def test_a_bad_kick_policy_is_a_configuration_error(tmp_path: Path) -> None:
    (tmp_path / "junk.npz").write_bytes(b"not a zip")
    with pytest.raises(StubConfigError) as err:
        _kick_policy(parse_args(["striker", "--kick-policy", str(tmp_path / "junk.npz")]))
    assert err.value.field == "--kick-policy" and "junk.npz" in err.value.value


def test_the_learned_kick_plays_the_policy_from_the_stance_and_returns_to_it() -> None:
    policy = make_policy(duration_s=0.2)
    stance = dict.fromkeys(MOTORS, 0.1)
    start = dict.fromkeys(MOTORS, 0.6)  # the head down at the ball, say
    start["M0"] = 1.0
    kick = LearnedKick(policy, start=start, stance=stance)
    joints = dict.fromkeys(MOTORS, 0.0)
    seen: list[tuple[float, int, dict[str, float]]] = []
    gains = []
    while not kick.done:
        kick.sense(joints, (0.0, 0.0, 9.8), (0.0, 0.0, 0.0))
        seen.append((kick.elapsed_s, kick.policy.decisions, kick.step(0.008)))
        gains.append((kick.policy.done, kick.servo_pid))
        assert len(seen) < 1000
    # the learnt gains until the policy has played, the stub's own for the recovery
    assert {g for done, g in gains if not done} == {LEARNT_SERVO_PID}
    assert gains[-1][1] == SERVO_PID
    ready = PREPARE_S + HOLD_S
    before = [(d, t) for s, d, t in seen if s < ready - 0.008]
    assert all(d == 0 for d, _ in before)  # no decision before the stance is reached and held
    assert before[0][1]["M0"] < 1.0 and before[0][1]["M0"] > 0.1  # eased, not jumped
    assert before[-1][1] == pytest.approx(stance)  # held
    assert kick.policy.decisions == 7  # 0.2 s of 32 ms decisions
    assert seen[-1][2] == pytest.approx(stance)  # back in the stance
    assert kick.elapsed_s == pytest.approx(ready + 0.2 + RECOVER_S, abs=0.02)
    # a policy longer than PLAY_S plays its first PLAY_S only
    long_kick = LearnedKick(make_policy(duration_s=1.5), start=start, stance=stance)
    while not long_kick.done:
        long_kick.sense(joints, (0.0, 0.0, 9.8), (0.0, 0.0, 0.0))
        long_kick.step(0.008)
    assert long_kick.policy.elapsed_s == pytest.approx(PLAY_S, abs=0.009)
    assert long_kick.elapsed_s == pytest.approx(ready + PLAY_S + RECOVER_S, abs=0.02)


def test_a_rising_model_is_handed_over_to_the_policy_as_the_environment_started_it() -> None:
    """adult-default's environment eases it into the stance over its 1 s rise and holds it
    0.5 s: the kick does the same before the policy's first decision; kid-default's is short."""
    assert handover_s(0.0) == (PREPARE_S, HOLD_S)
    assert handover_s(1.0) == (1.0, RISEN_HOLD_S)
    stance = dict.fromkeys(MOTORS, 0.1)
    start = dict.fromkeys(MOTORS, 0.6)
    joints = dict.fromkeys(MOTORS, 0.0)
    kick = LearnedKick(make_policy(duration_s=0.2), start=start, stance=stance, rise_s=1.0)
    first_decision_s, halfway = None, None
    while not kick.done and first_decision_s is None:
        kick.sense(joints, (0.0, 0.0, 9.8), (0.0, 0.0, 0.0))
        at = kick.elapsed_s
        targets = kick.step(0.008)
        if halfway is None and at >= 0.5:
            halfway = targets["M0"]
        if kick.policy.decisions:
            first_decision_s = at
    assert halfway == pytest.approx(0.35, abs=0.01)  # halfway from 0.6 to 0.1 after 0.5 s
    assert first_decision_s == pytest.approx(1.0 + RISEN_HOLD_S, abs=0.009)
    # the stub hands its model's rise to the kick
    adult = StubController(role=Role.STRIKER, start_pose=Pose(x_m=0, y_m=0, yaw_rad=0),
                           model="adult-default", field_class="adult",
                           kick_policy=make_policy())  # fmt: skip
    assert adult.kin.rise_s == 1.0
    adult._kick_choice.update((6.0, 0.0))  # the ball 1 m from the goal: a learned shot
    adult._kick(0.008, Sensors(time_ms=0, joints={}), "right", None)
    assert isinstance(adult._motion, LearnedKick)
    assert adult._motion._prepare.duration_s == pytest.approx(1.0 + RISEN_HOLD_S)


def test_the_stub_plays_a_learned_kick_with_the_servo_gains_it_learnt_with() -> None:
    controller = StubController(role=Role.STRIKER, start_pose=Pose(x_m=0, y_m=0, yaw_rad=0),
                                kick_policy=make_policy())  # fmt: skip
    assert controller.servo_pid == SERVO_PID
    controller._start(LearnedKick(make_policy(), start={}, stance={}), "kick")
    assert controller.servo_pid == LEARNT_SERVO_PID != SERVO_PID
    controller._finish_motion()
    assert controller.servo_pid == SERVO_PID


def test_a_right_footed_kick_off_striker_places_the_ball_at_its_right_foot() -> None:
    """In READY the kick-off striker stands with the ball short of its kick spot: the left
    foot's for the stub, the right foot's for one whose learned kick plays with it alone (from
    the left foot's spot it side-stepped at the kick-off and struck the ball's right side)."""
    game = GameInfo(phase=GameState.READY, our_kick_off=True)
    for feet, side in ((("left", "right"), 1.0), (("right",), -1.0)):
        field = Field(half_length_m=4.5, centre_circle_m=0.75, foot_y_m=0.075,
                      kick_x_m=KICK_BALL_AHEAD_M, kick_feet=feet)  # fmt: skip
        spot = _kick_off_position(Role.STRIKER, game, field, None)
        c, s = math.cos(spot.yaw_rad), math.sin(spot.yaw_rad)
        ahead, left = c * -spot.x_m + s * -spot.y_m, -s * -spot.x_m + c * -spot.y_m  # the ball
        assert ahead == pytest.approx(KICK_BALL_AHEAD_M + KICK_OFF_SHORT_M)
        assert left == pytest.approx(side * 0.075)


def test_the_adult_learned_kick_is_a_shot() -> None:
    """adult-default plays its learned kick within SHOT_RANGE_M of the opponent goal and the
    keyframe kick (either foot, at its own kick spot) farther out; kid-default plays it
    anywhere. Once lined up for the learned kick it keeps to it up to the margin beyond."""
    range_m = SHOT_RANGE_M["adult-default"]
    assert in_shot_range((7.0 - range_m + 0.1, 0.0), 7.0, range_m, now=False)
    assert not in_shot_range((7.0 - range_m - 0.1, 0.0), 7.0, range_m, now=False)
    assert not in_shot_range((6.0, range_m), 7.0, range_m, now=False)  # beside the goal, far
    assert in_shot_range((7.0 - range_m - 0.1, 0.0), 7.0, range_m, now=True)  # the margin
    beyond = 7.0 - range_m - SHOT_RANGE_MARGIN_M - 0.1
    assert not in_shot_range((beyond, 0.0), 7.0, range_m, now=True)
    assert in_shot_range((-4.0, 0.0), 7.0, None, now=False)  # no range: anywhere
    assert "kid-default" not in SHOT_RANGE_M

    at = Pose(x_m=0.0, y_m=0.0, yaw_rad=0.0)
    game = GameInfo(phase=GameState.PLAYING, our_kick_off=False)
    adult = StubController(role=Role.STRIKER, start_pose=at, model="adult-default",
                           field_class="adult", kick_policy=make_policy())  # fmt: skip
    keyframe_field = adult.field
    assert keyframe_field.kick_feet == ("left", "right")  # at its kick-off, far from the goal
    ahead, right = kick_ball_offset("adult-default")
    # the ball this far beyond the range from the goal's centre, in this order
    for beyond, learned in ((2.0, False), (0.2, False), (-0.5, True), (0.2, True),
                            (SHOT_RANGE_MARGIN_M + 0.1, False)):  # fmt: skip
        adult.field = adult._kick_choice.update((7.0 - range_m - beyond, 0.0))
        assert adult._kick_choice.learned is learned, beyond
        assert (adult.field.kick_x_m == ahead) is learned
        adult._kick(0.008, Sensors(time_ms=0, joints={}), "right", None)
        assert isinstance(adult._motion, LearnedKick) is learned, beyond
        adult._motion = None
    # far out, a ball in front of the left foot is kicked with it (the keyframe kick) ...
    left_ball = (keyframe_field.kick_x_m, keyframe_field.foot_y_m)
    far = decide(role=Role.STRIKER, game=game, pose=at, ball=left_ball, field=adult.field,
                 searching_s=0.0)  # fmt: skip
    assert far.kick_foot == "left"
    # ... near the goal the striker lines it up for the learned right-foot kick instead
    near_pose = Pose(x_m=5.0, y_m=0.0, yaw_rad=0.0)
    adult.field = adult._kick_choice.update(near_pose.to_field(*left_ball))
    near = decide(role=Role.STRIKER, game=game, pose=near_pose, ball=left_ball,
                  field=adult.field, searching_s=0.0)  # fmt: skip
    assert near.kick_foot is None and near.walk[1] > 0  # side-steps to its left
    # kid-default: the learned kick everywhere, from its kick-off on
    kid = StubController(role=Role.STRIKER, start_pose=at, kick_policy=make_policy())
    assert kid._kick_choice.learned and kid.field.kick_feet == ("right",)
    assert kid._kick_choice.update((-4.0, 0.0)).kick_feet == ("right",)
