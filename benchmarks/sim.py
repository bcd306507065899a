"""``python -m simulator bench sim``: speed of the world against a bare MuJoCo loop.

Measures ``World.step`` + ``World.snapshot`` with N robots holding the standing posture, and a bare
``mujoco.mj_step`` loop on the same model with the same physics time step. The two are run in
alternating one-second (simulated) chunks so that load from other processes affects both alike;
The world evaluates sensors only in the last physics substep of a basic step (they are read
once per step), the bare loop in every substep, as a plain ``mj_step`` loop does.
``cpu_ratio`` compares thread CPU time instead of wall time (steadier on a busy machine) and
``snapshot_us`` is the CPU time of one snapshot. Prints one JSON line with ``--json``::

    {"bench": "sim", "robots": 8, "sim_seconds": 20.0, "physics_dt_s": 0.002, "steps_per_s": ...,
     "real_time_factor": ..., "bare_real_time_factor": ..., "ratio": ..., "cpu_ratio": ...,
     "snapshot_us": ...}
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time
from typing import TYPE_CHECKING

if TYPE_CHECKING:  # MuJoCo and the world are imported after the arguments (fast --help)
    from simulator.world import RobotPlacement


def placements(count: int, model: str) -> list[RobotPlacement]:
    """``count`` robots alternating red and blue, spread over both halves."""
    from contracts.ids import RobotId, TeamColor
    from simulator.world import RobotPlacement

    out = []
    for i in range(count):
        team = TeamColor.RED if i % 2 == 0 else TeamColor.BLUE
        number = i // 2 + 1
        sign = -1.0 if team is TeamColor.RED else 1.0
        out.append(
            RobotPlacement(
                id=RobotId(team, number),
                model=model,
                x_m=sign * (0.8 + 0.8 * number),
                y_m=-1.5 + (number - 1) % 4,
                yaw_rad=0.0 if team is TeamColor.RED else 3.14159,
            )
        )
    return out


def run(
    *, robots: int, sim_seconds: float, physics_dt_s: float, field_class: str
) -> dict[str, object]:
    import mujoco

    from simulator.world import World
    from simulator.world.scene import compile_scene

    model_name = "kid-default" if field_class == "kid" else "adult-default"
    robot_list = placements(robots, model_name)
    world = World.create(
        field_class=field_class,  # type: ignore[arg-type]
        robots=robot_list,
        seed=0,
        physics_dt_s=physics_dt_s,
    )
    bare_model = compile_scene(world.field, robot_list, physics_dt_s=physics_dt_s)
    bare_data = mujoco.MjData(bare_model)
    steps_per_chunk = max(1, round(1000 / world.step_ms))
    substeps_per_chunk = steps_per_chunk * world.substeps
    chunks = max(1, round(sim_seconds))
    world_s = bare_s = snapshot_s = world_cpu = bare_cpu = 0.0
    clock = time.perf_counter
    cpu = time.thread_time
    for _ in range(chunks):
        start, start_cpu = clock(), cpu()
        for _ in range(steps_per_chunk):
            world.step()
            t = cpu()
            world.snapshot()
            snapshot_s += cpu() - t
        world_s += clock() - start
        world_cpu += cpu() - start_cpu
        start, start_cpu = clock(), cpu()
        for _ in range(substeps_per_chunk):
            mujoco.mj_step(bare_model, bare_data)
        bare_s += clock() - start
        bare_cpu += cpu() - start_cpu
    simulated = chunks * steps_per_chunk * world.step_ms / 1000.0
    steps = chunks * steps_per_chunk
    rtf = simulated / world_s
    bare = simulated / bare_s
    return {
        "bench": "sim",
        "robots": robots,
        "field_class": field_class,
        "sim_seconds": simulated,
        "physics_dt_s": physics_dt_s,
        "steps_per_s": round(steps / world_s, 1),
        "real_time_factor": round(rtf, 3),
        "bare_real_time_factor": round(bare, 3),
        "ratio": round(rtf / bare, 3),
        "cpu_ratio": round(bare_cpu / world_cpu, 3),
        "snapshot_us": round(snapshot_s / steps * 1e6, 1),
        "fallen": sum(r.fallen for r in world.snapshot().robots),
    }


def main(argv: list[str]) -> int:
    program = os.environ.get("HLVS_PROG", "python -m simulator")
    parser = argparse.ArgumentParser(prog=f"{program} bench sim")
    parser.add_argument("--robots", type=int, default=8, help="robots on the field (default 8)")
    parser.add_argument("--sim-seconds", type=float, default=20.0,
                        help="simulated seconds to run (default 20)")
    parser.add_argument("--physics-dt", type=float, default=0.002,
                        help="physics step in seconds (default 0.002)")
    parser.add_argument("--field", choices=("kid", "adult"), default="kid",
                        help="field size (default kid)")
    parser.add_argument("--json", action="store_true", help="print one JSON line")
    args = parser.parse_args(argv)
    if not 0 <= args.robots <= 29 or args.sim_seconds <= 0:
        print("error: --robots must be 0..29 and --sim-seconds positive", file=sys.stderr)
        return 2
    try:
        result = run(
            robots=args.robots,
            sim_seconds=args.sim_seconds,
            physics_dt_s=args.physics_dt,
            field_class=args.field,
        )
    except ValueError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    if args.json:
        print(json.dumps(result))
    else:
        for key, value in result.items():
            print(f"{key:>22}: {value}")
    return 0
