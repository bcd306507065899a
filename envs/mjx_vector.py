"""``hlvs/StandKick-v0`` as one batched MJX world: thousands of environments in one ``jax.vmap``.

``MjxStandKickVector(num_envs)`` is a :class:`gymnasium.vector.VectorEnv` with the spaces,
observations and reward of ``hlvs/StandKick-v0`` (:mod:`envs.stand_kick`): the robot API's
sensors and ``time``; the shaped reward of :func:`envs.stand_kick.stand_kick_reward` (the ball's
progress towards the goal centre, the toe's approach and the touch bonus, the cost of standing
still and of a fall); terminated on a fall, a goal or the ball out, truncated after
``max_episode_s``. It takes the CPU environment's settings
(:class:`envs.stand_kick.StandKickConfig`, fixed for the vector's life). The world is
:func:`envs.mjx_world.mjx_scene` (its module says where it differs from the CPU world).

Episodes start as the CPU environment's do, with one shortcut: the robot's settling in its
stance is computed once (:func:`envs.mjx_world.settled_state`, by the CPU world) and moved to
each episode's pose (``x`` 0.5-1.5 m, ``y`` +-1 m, facing the goal within
``heading_noise_rad``), the ball placed at the right foot (within ``ball_noise_m``), then one
environment step in the stance, as ``StandKickEnv.reset`` does.

Autoreset is Gymnasium's ``NEXT_STEP`` mode: the step after an episode ends starts the next
episode (the action given then is ignored; reward 0, neither terminated nor truncated). One
jitted function does a step and the resets, so the physics compiles once (its time is
``compile_s`` and ``compile_cpu_s`` after the first :meth:`reset`; :meth:`compiles` counts
the compiled versions, 1 once stepping). ``infos`` hold ``kick_distance_m``,
``ball_to_goal_m``, ``ball_speed_m_s``, ``max_ball_speed_m_s``, ``toe_to_ball_m``, ``touched``,
``ball_closer_m``, ``goal``, ``fallen``, ``out`` and ``sim_time_ms`` (numpy arrays, one value per
environment).
"""

from __future__ import annotations

import math
import time
from typing import Any

import numpy as np
from gymnasium import spaces
from gymnasium.vector import AutoresetMode, VectorEnv
from gymnasium.vector.utils import batch_space

from contracts import field_for
from envs.errors import EnvConfigError
from envs.frame import RIGHT_SOLE
from envs.skill import FALLEN_UP_Z
from envs.spaces import ACCEL_LIMIT, FORCE_LIMIT, GYRO_LIMIT, action_space, observation_space
from envs.stand_kick import (
    BALL_AHEAD_M,
    BALL_RIGHT_M,
    TIME_LIMIT_S,
    TOUCH_SPEED_M_S,
    StandKickConfig,
    stand_kick_reward,
)

STEP_MS = 8
DEFAULT_P = 10.0


def _quiet_import() -> Any:
    """``mujoco.mjx`` without the lines it prints when the optional Warp backend is missing."""
    import contextlib
    import io

    with contextlib.redirect_stdout(io.StringIO()):
        from mujoco import mjx
    return mjx


class MjxStandKickVector(VectorEnv):
    """``num_envs`` StandKick environments in one batched MJX world (see the module)."""

    metadata: dict[str, Any] = {"autoreset_mode": AutoresetMode.NEXT_STEP}

    def __init__(self, num_envs: int, *, self_collision: bool = False, **options: Any) -> None:
        """``options``: the settings of :class:`envs.stand_kick.StandKickConfig`.

        The step is built from named pieces, each a function traced into the one jitted step:
        :func:`_servo_step` (the servos and substeps), :func:`_measures` (the ball, the toe and
        the episode's end), :func:`_episode_start` (an episode's first state) and
        :func:`_env_step` (one environment step with its autoreset)."""
        if num_envs < 1:
            raise EnvConfigError(field="num_envs", value=num_envs, expected="an integer >= 1")
        config = self.config = StandKickConfig.of(options)
        if config.robot_class != "kid":
            raise EnvConfigError(field="robot_class", value=config.robot_class,
                                 expected="'kid' (the MJX world is the kid pitch's)",
                                 choices=("kid",))  # fmt: skip
        model, steps_per_action = config.model, config.steps_per_action
        import jax
        import jax.numpy as jnp

        from envs.mjx_world import LEARNER, mjx_scene, settled_state
        from simulator.world import robot_prefix

        mjx = _quiet_import()
        self.num_envs = num_envs
        self.steps_per_action = steps_per_action
        self.max_steps = math.ceil(config.max_episode_s * 1000 / (STEP_MS * steps_per_action))
        single = observation_space(model, camera=False, perception=False, other_robots=0,
                                   game=False)  # fmt: skip
        self.single_observation_space = spaces.Dict(
            {**single.spaces, "time": spaces.Box(0.0, TIME_LIMIT_S, (1,), np.float32)}
        )
        self.single_action_space = action_space(model)
        self.observation_space = batch_space(self.single_observation_space, num_envs)
        self.action_space = batch_space(self.single_action_space, num_envs)
        scene = mjx_scene(model=model, self_collision=self_collision)
        self.compiled = scene.model
        self.layout = layout = scene.layout
        servo = {k: jnp.asarray(v) for k, v in scene.servo.items()}
        qpos0, qvel0, stance = settled_state(model=model, steps_per_action=steps_per_action,
                                             settle_s=config.settle_s)  # fmt: skip
        self.stance = stance.astype(np.float32)
        mx = mjx.put_model(self.compiled)
        d0 = mjx.make_data(mx)
        substeps = round(STEP_MS / 1000.0 / self.compiled.opt.timestep)
        sole = self.compiled.geom(f"{robot_prefix(LEARNER)}/{RIGHT_SOLE}").id
        half_length = float(self.compiled.geom_size[sole][0])
        one = _env_step(
            config,
            layout,
            servo=servo,
            stance=stance,
            d0=d0,
            max_steps=self.max_steps,
            basic_step=_servo_step(mx, servo, layout, substeps=substeps),
            measures=_measures(layout, sole=sole, half_length=half_length),
            start=_episode_start(config, layout, d0=d0, qpos0=qpos0, qvel0=qvel0),
        )
        self._advance = jax.jit(jax.vmap(one))
        self._jnp = jnp
        self._jax = jax
        self._state: dict[str, Any] | None = None
        self._ended = np.zeros(num_envs, dtype=bool)
        self._sim_ms = np.zeros(num_envs, dtype=np.int64)
        self.compile_s: float | None = None  # wall seconds of the first reset (the jit)
        self.compile_cpu_s: float | None = None  # its CPU seconds (all threads)
        self._init_state = (d0, self.max_steps)

    def _initial(self, seed: int) -> dict[str, Any]:
        jax, jnp = self._jax, self._jnp
        d0 = self._init_state[0]
        n = self.num_envs
        keys = jax.random.split(jax.random.PRNGKey(seed), n)
        batched = jax.tree_util.tree_map(lambda a: jnp.broadcast_to(a, (n, *jnp.shape(a))), d0)
        f32 = jnp.float32
        state = {"key": keys, "d": batched, "steps": jnp.zeros(n, jnp.int32),
                "bg": jnp.zeros(n, f32), "t0": jnp.zeros(n, f32), "ball0": jnp.zeros((n, 2), f32),
                "top": jnp.zeros(n, f32), "gap": jnp.zeros(n, f32),
                "touched": jnp.zeros(n, bool)}  # fmt: skip
        return state

    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[dict[str, np.ndarray], dict[str, Any]]:
        if seed is None:
            seed = int(np.random.default_rng().integers(0, 2**31 - 1))
        state = self._initial(seed)
        actions = np.zeros((self.num_envs, 20), np.float32)
        began, cpu = time.perf_counter(), time.process_time()
        obs, _, _, _, info = self._run(state, actions, np.ones(self.num_envs, dtype=bool))
        if self.compile_s is None:
            self.compile_s = round(time.perf_counter() - began, 1)
            self.compile_cpu_s = round(time.process_time() - cpu, 1)
        return obs, info

    def step(
        self, actions: Any
    ) -> tuple[dict[str, np.ndarray], np.ndarray, np.ndarray, np.ndarray, dict[str, Any]]:
        if self._state is None:
            from envs.errors import EnvStateError

            raise EnvStateError(operation="step", reason="call reset() before step()")
        batch = np.asarray(actions, dtype=np.float32).reshape(self.num_envs, -1)
        if batch.shape[1] != 20:
            raise EnvConfigError(field="actions", value=f"shape {np.shape(actions)}",
                                 expected=f"shape ({self.num_envs}, 20)")  # fmt: skip
        return self._run(self._state, batch, self._ended)

    def _run(
        self, state: dict[str, Any], actions: np.ndarray, fresh: np.ndarray
    ) -> tuple[dict[str, np.ndarray], np.ndarray, np.ndarray, np.ndarray, dict[str, Any]]:
        # every argument committed to the device, as the step's outputs are: JAX keys its
        # compiled versions on that too, and a mix would compile the physics again
        args = self._jax.device_put((state, actions, fresh), self._jax.devices()[0])
        new, obs, reward, terminated, truncated, info = self._advance(*args)
        self._state = new
        joints, sensors, elapsed = (np.asarray(v, dtype=np.float32) for v in obs)
        terminated, truncated = np.asarray(terminated), np.asarray(truncated)
        self._ended = terminated | truncated
        sim_ms = np.rint(np.asarray(new["d"].time) * 1000).astype(np.int64)
        kick, bg, speed, top, gap, touched, goal, fallen, out = (np.asarray(v) for v in info)
        observation = {
            "joints": joints, "accelerometer": sensors[:, 0:3], "gyro": sensors[:, 3:6],
            "forces": sensors[:, 6:14], "time": elapsed.reshape(-1, 1),
        }  # fmt: skip
        infos = {
            "kick_distance_m": kick.astype(np.float64), "ball_to_goal_m": bg.astype(np.float64),
            "ball_speed_m_s": speed.astype(np.float64),
            "max_ball_speed_m_s": top.astype(np.float64),
            "toe_to_ball_m": gap.astype(np.float64), "touched": touched,
            "ball_closer_m": np.full(self.num_envs, self.config.ball_closer_m),
            "goal": goal, "fallen": fallen, "out": out, "sim_time_ms": sim_ms,
        }  # fmt: skip
        return observation, np.asarray(reward, dtype=np.float64), terminated, truncated, infos

    def compiles(self) -> int:
        """How many versions of the step function were compiled (1 in normal use)."""
        return int(self._advance._cache_size())  # type: ignore[attr-defined]

    def set_state(self, qpos: np.ndarray, qvel: np.ndarray) -> None:
        """Every environment's world to one MuJoCo state (``qpos``, ``qvel`` in the CPU world's
        layout, the same as the variant's), its episode going on from there: how a test runs
        both worlds from the same state."""
        if self._state is None:
            from envs.errors import EnvStateError

            raise EnvStateError(operation="set_state", reason="call reset() first")
        jnp = self._jnp
        d = self._state["d"]
        d = d.replace(
            qpos=jnp.broadcast_to(jnp.asarray(qpos, d.qpos.dtype), d.qpos.shape),
            qvel=jnp.broadcast_to(jnp.asarray(qvel, d.qvel.dtype), d.qvel.shape),
            qacc_warmstart=jnp.zeros_like(d.qacc_warmstart),
        )
        self._state = {**self._state, "d": d}
        self._ended = np.zeros(self.num_envs, dtype=bool)

    def close(self, **kwargs: Any) -> None:
        self._state = None


def _servo_step(mx: Any, servo: dict[str, Any], layout: Any, *, substeps: int) -> Any:
    """``basic_step(d, target)``: one basic step of ``substeps`` physics substeps with the
    servos driving the motors to ``target``."""
    import jax
    import jax.numpy as jnp

    mjx = _quiet_import()
    act = jnp.asarray(layout.actuators)
    mq, md = jnp.asarray(layout.motor_qpos), jnp.asarray(layout.motor_dof)

    def basic_step(d: Any, target: Any) -> Any:
        """MotorBank's position path, then the substeps (simulator.world.motors)."""
        q, qd = d.qpos[mq], d.qvel[md]
        error = target - q
        shift = jnp.clip(error, -servo["half_play"], servo["half_play"])
        error = error - shift
        wanted = DEFAULT_P * error
        limit = servo["velocity_limit"]
        free = jnp.abs(wanted) <= limit
        ctrl = jnp.where(free, DEFAULT_P * (target - shift), jnp.copysign(limit, wanted))
        on = (error != 0.0) | servo["no_play"]
        ctrl = ctrl * on
        bias_q = -servo["gain"] * DEFAULT_P * (free & on)
        bias_v = -servo["gain"] * on
        bounds = servo["line_bounds"] - (servo["line_slope"] * qd)[:, None]
        bounds = jnp.maximum(jnp.minimum(bounds, servo["bounds_high"]), servo["bounds_low"])
        gain = servo["gain"]
        low, high = bounds[:, 0], bounds[:, 1]

        def substep(_: Any, dd: Any) -> Any:
            # MuJoCo leaves a force clamped by its range out of the implicit integrator's
            # velocity derivative; MJX does not, so a clamped actuator becomes a plain torque
            force = gain * ctrl + bias_q * dd.qpos[mq] + bias_v * dd.qvel[md]
            clamped = (force < low) | (force > high)
            m = mx.replace(
                actuator_gainprm=mx.actuator_gainprm.at[act, 0].set(
                    jnp.where(clamped, 1.0, gain)
                ),
                actuator_biasprm=mx.actuator_biasprm.at[act, 1]
                .set(jnp.where(clamped, 0.0, bias_q))
                .at[act, 2]
                .set(jnp.where(clamped, 0.0, bias_v)),
                actuator_forcerange=jnp.asarray(mx.actuator_forcerange).at[act].set(bounds),
            )
            torque = jnp.where(clamped, jnp.clip(force, low, high), ctrl)
            return mjx.step(m, dd.replace(ctrl=dd.ctrl.at[act].set(torque)))

        return jax.lax.fori_loop(0, substeps, substep, d)

    return basic_step


def _measures(layout: Any, *, sole: int, half_length: float) -> Any:
    """``measures(d)``: the ball's distance to the goal centre, goal, fallen, out, the ball's
    speed and the gap between the right toe (``half_length`` ahead of the ``sole`` geom's
    centre) and the ball."""
    import jax.numpy as jnp

    field = field_for("kid")
    goal_x = field.half_length_m
    radius = field.ball_radius_m
    root_q, bq, bv = layout.root_qpos, layout.ball_qpos, layout.ball_dof
    torso = layout.torso_body

    def truth(d: Any) -> Any:
        w, x, y, z = (d.qpos[root_q + 3 + i] for i in range(4))
        yaw = jnp.arctan2(2 * (w * z + x * y), 1 - 2 * (y * y + z * z))
        up = d.xmat[torso, 2, 2]
        return d.qpos[bq : bq + 3], d.qvel[bv : bv + 3], d.qpos[root_q : root_q + 2], yaw, up

    def measures(d: Any) -> tuple[Any, Any, Any, Any, Any, Any]:
        ball, vel, _, _, up = truth(d)
        bg = jnp.hypot(goal_x - ball[0], ball[1])
        toe = d.geom_xpos[sole] + half_length * d.geom_xmat[sole][:, 0]
        gap = jnp.maximum(0.0, jnp.linalg.norm(toe - ball) - radius)
        x, y, z = ball[0], ball[1], ball[2]
        goal = (x - radius > goal_x) & (jnp.abs(y) < field.goal_width_m / 2)
        goal = goal & (z < field.goal_height_m)
        out = ~goal & (
            (jnp.abs(x) - radius > goal_x) | (jnp.abs(y) - radius > field.half_width_m)
        )
        return bg, goal, up < FALLEN_UP_Z, out, jnp.hypot(vel[0], vel[1]), gap

    return measures


def _episode_start(
    config: StandKickConfig, layout: Any, *, d0: Any, qpos0: np.ndarray, qvel0: np.ndarray
) -> Any:
    """``start(key)``: an episode's first state, the settled robot (``qpos0``, ``qvel0``)
    moved to a random pose facing the goal and the ball at its right foot."""
    import jax
    import jax.numpy as jnp

    field = field_for("kid")
    goal_x = field.half_length_m
    radius = field.ball_radius_m
    root_q, root_v, bq, bv = layout.root_qpos, layout.root_dof, layout.ball_qpos, layout.ball_dof
    template_q, template_v = jnp.asarray(qpos0), jnp.asarray(qvel0)
    ball_noise_m, heading_noise_rad = config.ball_noise_m, config.heading_noise_rad
    ball_ahead = BALL_AHEAD_M - config.ball_closer_m

    def start(key: Any) -> Any:
        """The episode's first state (before its stance step): the settled robot moved."""
        k = jax.random.split(key, 6)
        rx = jax.random.uniform(k[0], (), minval=0.5, maxval=1.5)
        ry = jax.random.uniform(k[1], (), minval=-1.0, maxval=1.0)
        yaw = jnp.arctan2(-ry, goal_x - rx) + jax.random.uniform(
            k[2], (), minval=-heading_noise_rad, maxval=heading_noise_rad)  # fmt: skip
        ahead = ball_ahead + jax.random.uniform(k[3], (), minval=-ball_noise_m,
                                                  maxval=ball_noise_m)  # fmt: skip
        right = BALL_RIGHT_M + jax.random.uniform(k[4], (), minval=-ball_noise_m,
                                                  maxval=ball_noise_m)  # fmt: skip
        c, s = jnp.cos(yaw), jnp.sin(yaw)
        qpos, qvel = template_q, template_v
        x0, y0 = qpos[root_q], qpos[root_q + 1]
        px, py = rx + c * x0 - s * y0, ry + s * x0 + c * y0
        half = jnp.array([jnp.cos(yaw / 2), 0.0, 0.0, jnp.sin(yaw / 2)])
        q0 = qpos[root_q + 3 : root_q + 7]
        quat = jnp.array([
            half[0] * q0[0] - half[3] * q0[3],
            half[0] * q0[1] - half[3] * q0[2],
            half[0] * q0[2] + half[3] * q0[1],
            half[0] * q0[3] + half[3] * q0[0],
        ])  # fmt: skip
        qpos = (
            qpos.at[root_q].set(px).at[root_q + 1].set(py).at[root_q + 3 : root_q + 7].set(quat)
        )
        vx, vy = qvel[root_v], qvel[root_v + 1]
        qvel = qvel.at[root_v].set(c * vx - s * vy).at[root_v + 1].set(s * vx + c * vy)
        w, _, _, z = quat[0], quat[1], quat[2], quat[3]
        ry2 = jnp.arctan2(2 * (w * z + quat[1] * quat[2]),
                          1 - 2 * (quat[2] ** 2 + z * z))  # fmt: skip
        cy, sy = jnp.cos(ry2), jnp.sin(ry2)
        bx, by = px + ahead * cy + right * sy, py + ahead * sy - right * cy
        qpos = qpos.at[bq : bq + 3].set(jnp.array([bx, by, radius]))
        qpos = qpos.at[bq + 3 : bq + 7].set(jnp.array([1.0, 0.0, 0.0, 0.0]))
        qvel = qvel.at[bv : bv + 6].set(0.0)
        return d0.replace(qpos=qpos.astype(d0.qpos.dtype), qvel=qvel.astype(d0.qvel.dtype))

    return start


def _env_step(
    config: StandKickConfig,
    layout: Any,
    *,
    servo: dict[str, Any],
    stance: np.ndarray,
    d0: Any,
    max_steps: int,
    basic_step: Any,
    measures: Any,
    start: Any,
) -> Any:
    """``one(state, action, fresh)``: one environment's step (``steps_per_action`` basic
    steps), or where ``fresh`` the start of its next episode and its stance step; the new
    state, the observation, the reward, terminated, truncated and the info values."""
    import jax
    import jax.numpy as jnp

    spa = config.steps_per_action
    penalty = float(config.fall_penalty)
    mq, bq = jnp.asarray(layout.motor_qpos), layout.ball_qpos
    sensor_at = jnp.asarray(layout.sensors)
    stance_j = jnp.asarray(stance)
    low = jnp.asarray([-ACCEL_LIMIT] * 3 + [-GYRO_LIMIT] * 3 + [0.0] * 8)
    high = jnp.asarray([ACCEL_LIMIT] * 3 + [GYRO_LIMIT] * 3 + [FORCE_LIMIT] * 8)

    def one(state: dict[str, Any], action: Any, fresh: Any) -> tuple[Any, ...]:
        key, sub = jax.random.split(state["key"])
        d = jax.tree_util.tree_map(lambda a, b: jnp.where(fresh, a, b), start(sub), state["d"])
        target = jnp.where(fresh, stance_j, jnp.clip(action, servo["lower"], servo["upper"]))
        d = jax.lax.fori_loop(0, spa, lambda _, dd: basic_step(dd, target), d)
        bg, goal, fallen, out, speed, gap = measures(d)
        steps = jnp.where(fresh, 0, state["steps"] + 1)
        before = jnp.where(fresh, False, state["touched"])
        touched = before | (speed >= TOUCH_SPEED_M_S)
        f32 = jnp.float32
        reward = stand_kick_reward(
            config, progress=state["bg"] - bg, gap_before=state["gap"], gap_after=gap,
            touched_before=before.astype(f32), touched=touched.astype(f32),
            fallen=fallen.astype(f32), fall_penalty=penalty,
        )  # fmt: skip
        touched = touched & ~fresh
        terminated = (goal | fallen | out) & ~fresh
        truncated = ~terminated & (steps >= max_steps) & ~fresh
        t0 = jnp.where(fresh, d.time, state["t0"])
        ball = d.qpos[bq : bq + 2]
        ball0 = jnp.where(fresh, ball, state["ball0"])
        top = jnp.where(fresh, 0.0, jnp.maximum(state["top"], speed))
        sensors = jnp.clip(d.sensordata[sensor_at], low, high)
        joints = jnp.clip(d.qpos[mq], -jnp.pi, jnp.pi)
        d = jax.tree_util.tree_map(lambda a, b: a.astype(b.dtype), d, d0)  # no weak types
        new = {"key": key, "d": d, "steps": steps.astype(jnp.int32),
               "bg": bg.astype(jnp.float32), "t0": t0.astype(jnp.float32),
               "ball0": ball0.astype(jnp.float32), "top": top.astype(jnp.float32),
               "gap": gap.astype(jnp.float32), "touched": touched}  # fmt: skip
        obs = (joints, sensors, d.time - t0)
        info = (jnp.hypot(*(ball - ball0)), bg, speed, top, gap, touched, goal, fallen, out)
        return new, obs, jnp.where(fresh, 0.0, reward), terminated, truncated, info

    return one
