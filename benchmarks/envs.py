"""``hlvs bench envs``: environment steps per second, in-process and over remotes. One JSON line.

In-process: ``hlvs/Kick-v0`` made with ``gymnasium.make`` (its wrappers included) against bare
world stepping of the same model in the same process (a world with the same robot, the same motor
targets written with ``set_motor_positions`` then ``step()``, what a hand-written loop does).
The two alternate in blocks of ``--block`` steps for ``--rounds`` rounds, so load from other
processes hits both alike; rates are computed from the step thread's CPU time (``cpu``) and from
wall time (``wall``). ``ratio`` = env steps/s over bare steps/s (CPU time); the target is >= 0.8.

Vectorised in-process (``vector_inprocess``): ``envs.vector.make_vector("hlvs/Kick-v0",
remotes=None, num_envs=--num-envs, steps_per_action=--steps-per-action)`` against as many bare
worlds, each given its targets and stepped ``--steps-per-action`` times per environment step
(the same robots, the same control period), alternating in the same way; its ``ratio`` is the
target of the vector environment (>= 0.8).

With ``--mjx-envs N`` (needs ``mujoco-mjx``, the ``[learn]`` extra), it also measures
``hlvs/StandKick-v0`` batched on MJX (``envs.mjx_vector.MjxStandKickVector``, N environments in
one ``jax.vmap``) on JAX's first device (``mjx.device``: ``cpu`` unless a GPU is installed):
``compile_s`` (building the world and the first ``jax.jit`` of its step, with the first reset),
then ``--mjx-steps`` batched steps near the stance, in environment steps per second of wall
time and of the process's CPU time (JAX uses every core). Off by default: the compile takes
minutes on a CPU.

With ``--remotes N`` (needs Docker and the simulator image), it also measures one remote over
TCP and a vector environment over 1, 2, ... N remotes (``--vector 1,2,4``, each size
``--repeats`` times, interleaved), with the client's and the remotes' CPU time per step, at the
same ``--steps-per-action``.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from typing import Any

from benchmarks.envs_actions import actions as random_actions


def bench_inprocess(*, rounds: int, block: int, seed: int) -> dict[str, Any]:
    import gymnasium as gym
    import numpy as np

    import envs  # noqa: F401  (registers the ids)
    from referee import RobotId, TeamColor
    from simulator.world import MOTOR_NAMES, RobotPlacement, World

    env = gym.make("hlvs/Kick-v0", max_episode_s=3600.0)
    env.reset(seed=seed)
    bare = World.create(
        field_class="kid",
        robots=[
            RobotPlacement(
                id=RobotId(TeamColor.RED, 1), model="kid-default", x_m=0.0, y_m=0.0, yaw_rad=0.0
            )
        ],  # fmt: skip
        seed=seed,
    )
    robot = RobotId(TeamColor.RED, 1)
    actions = random_actions(block, seed)
    bare_actions = actions.astype(np.float64)
    totals = {"env_cpu": 0.0, "env_wall": 0.0, "bare_cpu": 0.0, "bare_wall": 0.0}
    for _ in range(rounds):
        c0, w0 = time.thread_time(), time.perf_counter()
        for a in actions:
            _, _, terminated, truncated, _ = env.step(a)
            if terminated or truncated:
                env.reset()
        c1, w1 = time.thread_time(), time.perf_counter()
        for a in bare_actions:
            bare.set_motor_positions(robot, MOTOR_NAMES, a)
            bare.step()
        c2, w2 = time.thread_time(), time.perf_counter()
        totals["env_cpu"] += c1 - c0
        totals["env_wall"] += w1 - w0
        totals["bare_cpu"] += c2 - c1
        totals["bare_wall"] += w2 - w1
    env.close()
    steps = rounds * block
    rates = {k: steps / v for k, v in totals.items() if v > 0}
    return {
        "env_steps_per_s_cpu": round(rates["env_cpu"], 1),
        "bare_steps_per_s_cpu": round(rates["bare_cpu"], 1),
        "env_steps_per_s_wall": round(rates["env_wall"], 1),
        "bare_steps_per_s_wall": round(rates["bare_wall"], 1),
        "ratio": round(rates["env_cpu"] / rates["bare_cpu"], 3),
        "ratio_wall": round(rates["env_wall"] / rates["bare_wall"], 3),
        "steps": steps,
    }


def bench_vector_inprocess(
    *, rounds: int, block: int, seed: int, num_envs: int, steps_per_action: int
) -> dict[str, Any]:
    import numpy as np

    import envs  # noqa: F401  (registers the ids)
    from envs.vector import make_vector
    from referee import RobotId, TeamColor
    from simulator.world import MOTOR_NAMES, RobotPlacement, World

    vec = make_vector("hlvs/Kick-v0", remotes=None, num_envs=num_envs, max_episode_s=3600.0,
                      steps_per_action=steps_per_action)  # fmt: skip
    vec.reset(seed=seed)
    robot = RobotId(TeamColor.RED, 1)
    bare = [
        World.create(field_class="kid", seed=seed + i, robots=[
            RobotPlacement(id=robot, model="kid-default", x_m=0.0, y_m=0.0, yaw_rad=0.0)])
        for i in range(num_envs)
    ]  # fmt: skip
    actions = random_actions(block * num_envs, seed).reshape(block, num_envs, 20)
    bare_actions = actions.astype(np.float64)
    totals = {"env_cpu": 0.0, "env_wall": 0.0, "bare_cpu": 0.0, "bare_wall": 0.0}
    for _ in range(rounds):
        c0, w0 = time.thread_time(), time.perf_counter()
        for a in actions:
            vec.step(a)
        c1, w1 = time.thread_time(), time.perf_counter()
        for a in bare_actions:
            for world, targets in zip(bare, a, strict=True):
                world.set_motor_positions(robot, MOTOR_NAMES, targets)
                for _ in range(steps_per_action):
                    world.step()
        c2, w2 = time.thread_time(), time.perf_counter()
        totals["env_cpu"] += c1 - c0
        totals["env_wall"] += w1 - w0
        totals["bare_cpu"] += c2 - c1
        totals["bare_wall"] += w2 - w1
    vec.close()
    steps = rounds * block * num_envs  # environment steps (each steps_per_action world steps)
    rates = {k: steps / v for k, v in totals.items() if v > 0}
    return {
        "num_envs": num_envs,
        "steps_per_action": steps_per_action,
        "env_steps_per_s_cpu": round(rates["env_cpu"], 1),
        "bare_steps_per_s_cpu": round(rates["bare_cpu"], 1),
        "env_steps_per_s_wall": round(rates["env_wall"], 1),
        "bare_steps_per_s_wall": round(rates["bare_wall"], 1),
        "ratio": round(rates["env_cpu"] / rates["bare_cpu"], 3),
        "ratio_wall": round(rates["env_wall"] / rates["bare_wall"], 3),
        "steps": steps,
    }


def bench_mjx(*, num_envs: int, steps: int, seed: int) -> dict[str, Any]:
    import jax

    from envs.mjx_vector import MjxStandKickVector

    began = time.perf_counter()
    vec = MjxStandKickVector(num_envs)
    built_s = time.perf_counter() - began
    vec.reset(seed=seed)
    assert vec.compile_s is not None
    actions = vec.stance + random_actions(num_envs, seed)
    vec.step(actions)  # the first call after the compile
    c0, w0 = time.process_time(), time.perf_counter()
    for _ in range(steps):
        vec.step(actions)
    c1, w1 = time.process_time(), time.perf_counter()
    vec.close()
    device = jax.devices()[0]
    total = steps * num_envs
    return {
        "env": "hlvs/StandKick-v0",
        "device": f"{device.platform}:{getattr(device, 'device_kind', '')}",
        "num_envs": num_envs,
        "steps_per_action": vec.steps_per_action,
        "build_s": round(built_s, 1),
        "compile_s": vec.compile_s,
        "compile_cpu_s": vec.compile_cpu_s,
        "compiles": vec.compiles(),
        "env_steps_per_s_wall": round(total / (w1 - w0), 1),
        "env_steps_per_s_cpu": round(total / max(c1 - c0, 1e-9), 1),
        "steps": total,
    }


def main(argv: list[str]) -> int:
    parser = argparse.ArgumentParser(prog="hlvs bench envs")
    parser.add_argument("--rounds", type=int, default=10, help="alternating rounds")
    parser.add_argument("--block", type=int, default=500, help="steps per block")
    parser.add_argument("--seed", type=int, default=1, help="episode and action seed")
    parser.add_argument("--num-envs", type=int, default=4,
                        help="environments of the in-process vector environment")
    parser.add_argument("--steps-per-action", type=int, default=4,
                        help="8 ms world steps per environment step of the vector environment "
                        "(default 4: the 32 ms of examples/learn_stand_kick.py)")
    parser.add_argument("--mjx-envs", type=int, default=0,
                        help="also measure hlvs/StandKick-v0 batched on MJX with N environments "
                        "(compiles for minutes on a CPU; default 0: not measured)")
    parser.add_argument("--mjx-steps", type=int, default=20, help="batched MJX steps timed")
    parser.add_argument("--remotes", type=int, default=0, help="also measure N remotes (Docker)")
    parser.add_argument("--vector", default="1,2,4", help="vector sizes over remotes")
    parser.add_argument("--remote-steps", type=int, default=1000, help="steps per remote run")
    parser.add_argument("--repeats", type=int, default=1,
                        help="runs of each vector size, interleaved (medians reported)")
    parser.add_argument("--json", action="store_true", help="only the JSON line")
    args = parser.parse_args(argv)
    if min(args.rounds, args.block, args.repeats, args.num_envs, args.steps_per_action) < 1:
        print("--rounds, --block, --repeats, --num-envs and --steps-per-action: expected "
              "integers >= 1", file=sys.stderr)  # fmt: skip
        return 2
    out: dict[str, Any] = {"bench": "envs", "env": "hlvs/Kick-v0", "seed": args.seed}
    out["inprocess"] = bench_inprocess(rounds=args.rounds, block=args.block, seed=args.seed)
    out["vector_inprocess"] = bench_vector_inprocess(
        rounds=args.rounds, block=max(1, args.block // args.num_envs), seed=args.seed,
        num_envs=args.num_envs, steps_per_action=args.steps_per_action,
    )  # fmt: skip
    if args.mjx_envs < 0 or args.mjx_steps < 1:
        print("--mjx-envs: expected an integer >= 0; --mjx-steps: >= 1", file=sys.stderr)
        return 2
    if args.mjx_envs > 0:
        out["mjx"] = bench_mjx(num_envs=args.mjx_envs, steps=args.mjx_steps, seed=args.seed)
    if args.remotes > 0:
        from benchmarks.envs_remote import bench_remotes

        sizes = [int(v) for v in args.vector.split(",") if v.strip()]
        out.update(bench_remotes(remotes=args.remotes, sizes=sizes, steps=args.remote_steps,
                                 seed=args.seed, repeats=args.repeats,
                                 steps_per_action=args.steps_per_action))  # fmt: skip
    print(json.dumps(out))
    return 0
