"""The soccer world of ``hlvs/StandKick-v0`` batched on MJX (MuJoCo in JAX): one ``jax.vmap``.

The model is the CPU world's own compiled scene (``World.create``: the same field, goals, ball
and robot MJCF, the ball's damping) in an explicit MJX variant, :func:`mjx_scene`, which differs
from the CPU world in what MJX (``mujoco-mjx``, its JAX backend) does not implement:

- the robot's ball-touch sensor (a ``contact`` sensor matching the torso's subtree) reads the
  clock instead: MJX has no subtree contact sensor. It only counts touches for the referee; no
  force or observation depends on it;
- the goals' collision geoms collide with the ball only, not with the robot (the nets' cords,
  visual only, stay without contacts): MJX has no collision
  function for a cylinder (post, crossbar) against a box (the robot's links). In
  ``hlvs/StandKick-v0`` the robot starts 3 m or more from either goal and its episode lasts
  1.5 s, so it never reaches one;
- by default the robot's links do not collide with each other (``self_collision=False``): the
  186 link pairs made the first ``jax.jit`` of a step take over six minutes on two loaded CPU
  cores. A standing kick rarely brings two links together, but a leg crossing the other
  passes through it here.

Everything else is MuJoCo's own model: the ``implicitfast`` integrator, the pyramidal friction
cone, the Newton solver with the model's iteration counts, ``condim`` 3 (links) and 6 (ball,
rolling friction), the joints' friction loss and damping. MJX computes in float32 unless JAX's
``jax_enable_x64`` is set (the CPU world is float64), and its Newton solver and collision
routines are re-implementations. One actuator rule differs and is restored by
:mod:`envs.mjx_vector`: MuJoCo leaves an actuator whose force its range clamps out of the
``implicitfast`` velocity derivative, MJX does not (a swinging leg then lagged 0.2 rad in 0.2 s).
``tests/unit/envs/test_envs_mjx.py`` runs both worlds from one state through a kick that moves
the ball 0.25 m: joints within 5e-6 rad, torso and ball within 4e-5 m after 0.5 s.

The servos are the CPU world's (:mod:`simulator.world.motors`) in its common case: position
control with ``P`` 10 and no ``I`` or ``D`` (what every environment step commands), the backlash
and the torque-speed line. Once per basic step (8 ms) each environment's gains, biases and force
ranges are computed from its joints' positions and velocities, as ``MotorBank.apply`` does, and
the physics then takes its substeps (sensors evaluated in the last one only, as on the CPU).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import mujoco
import numpy as np

from contracts import RobotId, TeamColor
from simulator.world import RobotPlacement, World, robot_prefix

GOAL_BIT = 1 << 28  # the goals' own contype in the variant: no robot geom has it in conaffinity
LEARNER = RobotId(TeamColor.RED, 1)
DIFFERENCES = (
    "the ball-touch contact sensor reads the clock (MJX has no subtree contact sensor)",
    "goal geoms collide with the ball only (MJX has no cylinder-box collision)",
    "no collisions between the robot's own links unless self_collision=True (compile time)",
    "float32 arithmetic unless jax_enable_x64 (the CPU world is float64)",
    "MJX's own Newton solver and box-plane / sphere-box contact routines",
    "MJX keeps clamped actuator forces in the implicitfast derivative (envs.mjx_vector makes "
    "them plain torques, as MuJoCo treats them)",
)


@dataclass(frozen=True)
class RobotLayout:
    """Where the learning robot's quantities sit in the model (numpy index arrays)."""

    actuators: np.ndarray
    motor_qpos: np.ndarray
    motor_dof: np.ndarray
    root_qpos: int
    root_dof: int
    torso_body: int
    ball_qpos: int
    ball_dof: int
    sensors: np.ndarray  # sensordata indices: accelerometer (3), gyro (3), forces (8)


@dataclass(frozen=True)
class MjxScene:
    """The variant model, the robot's layout in it and its servos' constants."""

    model: mujoco.MjModel
    layout: RobotLayout
    servo: dict[str, np.ndarray]


def mjx_scene(*, model: str = "kid-default", self_collision: bool = False) -> MjxScene:
    """The MJX variant of the one-robot skill world on the kid pitch (the robot at the origin
    facing +x): the CPU world's compiled model (``World.create``) with the changes the module
    lists. Without ``self_collision`` (the default) the robot's links do not collide with each
    other: 186 link pairs (sphere, capsule and box pairs) that multiply MJX's compile time on
    the CPU; with it, what the CPU world has."""
    from envs.frame import SENSOR_NAMES

    placement = RobotPlacement(id=LEARNER, model=model, x_m=0.0, y_m=0.0, yaw_rad=0.0)
    world = World.create(field_class="kid", robots=[placement], seed=0)
    compiled = world.model
    touch = compiled.sensor(f"{robot_prefix(LEARNER)}/ball_touch").id
    if compiled.sensor_type[touch] != mujoco.mjtSensor.mjSENS_CONTACT or compiled.sensor_dim[
        touch
    ] != 1:
        raise RuntimeError("the world's ball-touch sensor is not a one-value contact sensor")
    compiled.sensor_type[touch] = mujoco.mjtSensor.mjSENS_CLOCK
    compiled.sensor_objtype[touch] = mujoco.mjtObj.mjOBJ_UNKNOWN
    compiled.sensor_objid[touch] = -1
    compiled.sensor_reftype[touch] = mujoco.mjtObj.mjOBJ_UNKNOWN
    compiled.sensor_refid[touch] = -1
    compiled.sensor_intprm[touch] = 0
    compiled.sensor_needstage[touch] = mujoco.mjtStage.mjSTAGE_POS
    ball_bit = int(compiled.geom("ball:geom").contype[0])
    static_bit = int(compiled.geom_contype[0])  # the turf, the world body's first geom
    prefix = f"{robot_prefix(LEARNER)}/"
    for g in range(compiled.ngeom):
        name = compiled.geom(g).name
        collides = bool(compiled.geom_contype[g] or compiled.geom_conaffinity[g])
        if name.startswith(("goal_left", "goal_right")) and collides:  # not the nets' cords
            compiled.geom_contype[g] = GOAL_BIT
            compiled.geom_conaffinity[g] = ball_bit
        elif not self_collision and name.startswith(prefix):
            compiled.geom_conaffinity[g] &= static_bit | ball_bit  # the robot bit off
    index = world.index
    robot = index.by_id[LEARNER]
    a, g = robot.accelerometer, robot.gyro
    forces = [robot.forces[name] for name in SENSOR_NAMES[len(robot.motor_qpos) + 2 :]]
    root_joint = int(compiled.body_jntadr[robot.torso_body])
    layout = RobotLayout(
        actuators=np.asarray(robot.actuators, dtype=np.int64),
        motor_qpos=np.asarray(robot.motor_qpos, dtype=np.int64),
        motor_dof=np.array(
            [int(compiled.jnt_dofadr[compiled.actuator_trnid[i, 0]]) for i in robot.actuators],
            dtype=np.int64,
        ),
        root_qpos=int(robot.root_qpos),
        root_dof=int(compiled.jnt_dofadr[root_joint]),
        torso_body=int(robot.torso_body),
        ball_qpos=int(index.ball_qpos),
        ball_dof=int(index.ball_dof),
        sensors=np.array([a, a + 1, a + 2, g, g + 1, g + 2, *forces], dtype=np.int64),
    )
    params = world.motors.params  # sorted by actuator id, as layout.actuators of one robot
    if not np.array_equal(np.arange(compiled.nu)[params.actuators], layout.actuators):
        raise RuntimeError("the robot's actuators are not the model's in order")
    servo: dict[str, Any] = {
        "gain": params.gain,
        "half_play": params.half_play,
        "no_play": params.no_play,
        "line_bounds": params.line_bounds,
        "bounds_low": params.bounds_low,
        "bounds_high": params.bounds_high,
        "line_slope": params.line_slope,
        "velocity_limit": params.max_velocity,
        "lower": params.lower,
        "upper": params.upper,
    }
    return MjxScene(model=compiled, layout=layout, servo=servo)


def settled_state(
    *, model: str = "kid-default", steps_per_action: int = 4, settle_s: float = 0.5, seed: int = 0
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(qpos, qvel, stance) of the robot settled in its stance at the origin facing +x, ball
    aside at (-3, 0): ``hlvs/StandKick-v0``'s settling, run once by the CPU world. The skill
    world is the same under a move on the flat pitch, so each episode moves this state to its
    own pose instead of settling again."""
    import math

    from contracts import field_for
    from referee import PlaceBall
    from robot.motion import standing_posture
    from simulator.world import MOTOR_NAMES

    field = field_for("kid")
    world = World.create(
        field_class="kid", seed=seed,
        robots=[RobotPlacement(id=LEARNER, model=model, x_m=0.0, y_m=0.0, yaw_rad=0.0)],
    )  # fmt: skip
    world.apply(PlaceBall(position=(-3.0, 0.0, field.ball_radius_m)))
    posture = standing_posture(model)
    stance = np.array([posture.get(name, 0.0) for name in MOTOR_NAMES])
    settle_steps = math.ceil(settle_s * 1000 / (8 * steps_per_action))
    for _ in range(settle_steps * steps_per_action):
        world.set_motor_positions(LEARNER, MOTOR_NAMES, stance.tolist())
        world.step()
    return world.data.qpos.copy(), world.data.qvel.copy(), stance
