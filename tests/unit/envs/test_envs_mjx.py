"""The MJX world of hlvs/StandKick-v0 against the CPU world: its variant, its observations, and
both worlds run from the same state with the same actions (trajectories within stated bounds).

One batched world of two environments is built and compiled for the module (the first
``jax.jit`` of the step is most of this file's time; ``compile_s`` is printed)."""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("mujoco.mjx")

import mujoco  # noqa: E402

from contracts import field_for  # noqa: E402
from envs.mjx_world import LEARNER, mjx_scene  # noqa: E402
from simulator.world import MOTOR_NAMES, RobotPlacement, World  # noqa: E402
from simulator.world.scene import compile_scene  # noqa: E402

pytestmark = pytest.mark.slow

STEPS = 16  # environment steps of 32 ms compared (0.512 s: the right leg back, then into the ball)
SWING = 5  # steps with the leg drawn back
# (right hip pitch, right knee) offsets from the stance while drawn back, then swinging
BACK_RAD = (-0.6, -0.8)
SWING_RAD = (0.9, 0.0)
# bounds over those steps: MJX in float32 against the CPU world in float64. Measured (the ball
# kicked 0.25 m): joints 4.8e-6 rad, torso 7.4e-7 m, ball 3.5e-5 m; the bounds leave room for
# float32 rounding on other machines, far below what a different servo or contact law gives
# (without the clamped-actuator rule of envs.mjx_vector: joints 0.20 rad, ball 0.079 m)
JOINT_TOL_RAD = 1e-3
TORSO_TOL_M = 1e-3
BALL_TOL_M = 1e-3


@pytest.fixture(scope="module")
def vector():
    from envs.mjx_vector import MjxStandKickVector

    vec = MjxStandKickVector(2)
    vec.reset(seed=3)
    print(f"MJX compile_s {vec.compile_s} (CPU {vec.compile_cpu_s})")
    yield vec
    vec.close()


def test_variant_keeps_the_cpu_worlds_layout_and_leaves_out_what_mjx_lacks() -> None:
    from mujoco import mjx
    from mujoco.mjx._src import collision_driver

    variant = mjx_scene().model
    placement = RobotPlacement(id=LEARNER, model="kid-default", x_m=0.0, y_m=0.0, yaw_rad=0.0)
    full = compile_scene(field_for("kid"), [placement], physics_dt_s=0.002)
    assert (variant.nq, variant.nv, variant.nu) == (full.nq, full.nv, full.nu)
    assert variant.nsensor == full.nsensor
    kinds = set(variant.sensor_type.tolist()) ^ set(full.sensor_type.tolist())
    assert kinds == {int(mujoco.mjtSensor.mjSENS_CONTACT), int(mujoco.mjtSensor.mjSENS_CLOCK)}
    assert variant.opt.integrator == full.opt.integrator
    assert variant.opt.cone == full.opt.cone and variant.opt.solver == full.opt.solver
    np.testing.assert_array_equal(variant.dof_damping, full.dof_damping)
    np.testing.assert_array_equal(variant.dof_frictionloss, full.dof_frictionloss)
    names = [
        (variant.geom(g1).name, variant.geom(g2).name)
        for g1, g2, _ in collision_driver.geom_pairs(variant)
    ]
    assert any(a.startswith("goal_right") or b.startswith("goal_right") for a, b in names)
    for a, b in names:  # goals meet the ball only; robot links never each other
        if a.startswith("goal") or b.startswith("goal"):
            assert "ball:geom" in (a, b)
        assert not (a.startswith("red_1/") and b.startswith("red_1/"))
    with_self = mjx_scene(self_collision=True).model
    assert any(
        with_self.geom(g1).name.startswith("red_1/")
        and with_self.geom(g2).name.startswith("red_1/")
        for g1, g2, _ in collision_driver.geom_pairs(with_self)
    )
    mjx.put_model(variant)  # MJX accepts it (the CPU world's model it refuses)
    with pytest.raises(NotImplementedError):
        mjx.put_model(full)


def test_observations_are_the_cpu_envs(vector) -> None:
    import gymnasium as gym

    import envs  # noqa: F401

    cpu = gym.make("hlvs/StandKick-v0")
    try:
        space = cpu.observation_space
        obs, info = vector.reset(seed=5)
        assert set(obs) == set(space.spaces)
        for i in range(vector.num_envs):
            assert space.contains({k: v[i] for k, v in obs.items()})
        assert vector.single_action_space == cpu.action_space
        assert np.all(obs["time"] == 0.0)
        assert np.all(info["kick_distance_m"] == 0.0)
        # the ball at the right foot, the robot up, in the attacking half
        assert np.all((info["ball_to_goal_m"] > 2.5) & (info["ball_to_goal_m"] < 4.5))
        assert not info["fallen"].any()
    finally:
        cpu.close()


def test_trajectories_follow_the_cpu_world_from_the_same_state(vector) -> None:
    vector.reset(seed=11)
    state = vector._state
    assert state is not None
    qpos = np.asarray(state["d"].qpos[0], dtype=np.float64)
    qvel = np.asarray(state["d"].qvel[0], dtype=np.float64)
    world = World.create(
        field_class="kid", seed=0,
        robots=[RobotPlacement(id=LEARNER, model="kid-default", x_m=0.0, y_m=0.0, yaw_rad=0.0)],
    )  # fmt: skip
    world.data.qpos[:] = qpos
    world.data.qvel[:] = qvel
    world.data.qacc_warmstart[:] = 0.0
    mujoco.mj_forward(world.model, world.data)
    vector.set_state(qpos, qvel)
    layout = vector.layout
    hip, knee = MOTOR_NAMES.index("LegUpperR"), MOTOR_NAMES.index("LegLowerR")
    gaps = {"joints": 0.0, "torso": 0.0, "ball": 0.0}
    ball_moved = 0.0
    root, bq = layout.root_qpos, layout.ball_qpos
    for t in range(STEPS):
        action = vector.stance.copy()
        offsets = BACK_RAD if t < SWING else SWING_RAD
        action[hip] += offsets[0]
        action[knee] += offsets[1]
        for _ in range(vector.steps_per_action):
            world.set_motor_positions(LEARNER, MOTOR_NAMES, action.astype(np.float64))
            world.step()
        obs, _, terminated, truncated, _ = vector.step(np.tile(action, (2, 1)))
        assert not (terminated.any() or truncated.any())
        d = vector._state["d"]
        mq = np.asarray(d.qpos[0])
        cq = world.data.qpos
        gaps["joints"] = max(
            gaps["joints"], float(np.abs(mq[layout.motor_qpos] - cq[layout.motor_qpos]).max())
        )
        gaps["torso"] = max(
            gaps["torso"], float(np.abs(mq[root : root + 3] - cq[root : root + 3]).max())
        )
        gaps["ball"] = max(gaps["ball"], float(np.abs(mq[bq : bq + 3] - cq[bq : bq + 3]).max()))
        ball_moved = float(np.hypot(*(cq[bq : bq + 2] - qpos[bq : bq + 2])))
        np.testing.assert_allclose(obs["joints"][0], obs["joints"][1], atol=1e-6)  # one state
    print(f"MJX vs CPU over {STEPS} steps: {gaps}; CPU ball moved {ball_moved:.3f} m")
    assert ball_moved > 0.05  # the kick reached the ball: contacts were compared too
    print(f"MJX compiled versions: {vector.compiles()}")
    assert vector.compiles() == 1  # resets and steps share one compiled function
    assert gaps["joints"] <= JOINT_TOL_RAD
    assert gaps["torso"] <= TORSO_TOL_M
    assert gaps["ball"] <= BALL_TOL_M
