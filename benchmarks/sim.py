"""``python -m benchmarks sim``: speed of the world against a bare MuJoCo loop.

Measures ``World.step`` + ``World.snapshot`` with N robots holding the standing posture, and a bare
``mujoco.mj_step`` loop on the same model with the same physics time step. The two are run in
alternating chunks of 250 ms (simulated) so that load from other processes affects both alike,
after two untimed chunks of each (:data:`WARMUP_CHUNKS`). The world evaluates sensors only in
the last physics substep of a basic step (they are read once per step), the bare loop in every
substep, as a plain ``mj_step`` loop does.
``cpu_ratio`` compares thread CPU time instead of wall time (steadier on a busy machine),
``ratio_pair_median`` is the median of the ratios of adjacent chunk pairs, and
``snapshot_us`` is the CPU time of one snapshot. Prints one JSON line with ``--json``::

    {"bench": "sim", "robots": 8, "sim_seconds": 20.0, "physics_dt_s": 0.002, "steps_per_s": ...,
     "real_time_factor": ..., "bare_real_time_factor": ..., "ratio": ..., "cpu_ratio": ...,
     "snapshot_us": ...}
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import sys
import time
from typing import TYPE_CHECKING

if TYPE_CHECKING:  # MuJoCo and the world are imported after the arguments (fast --help)
    from simulator.world import RobotPlacement

CHUNK_MS = 250  # simulated time of each alternating chunk (as bench api's interleaving)
WARMUP_CHUNKS = 2  # untimed chunks of each loop first: the robots settle on the turf, the
# snapshot's contact classifications and numpy's first calls are made, as in a match's first
# second; a 2 s run timed from the first step spread 0.94-1.03 where 8 s runs gave 0.98-1.07


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
    steps_per_chunk = max(1, round(CHUNK_MS / world.step_ms))
    steps = max(1, round(sim_seconds * 1000 / world.step_ms))
    world_s = bare_s = snapshot_s = world_cpu = bare_cpu = 0.0
    pair_ratios: list[float] = []
    clock = time.perf_counter
    cpu = time.thread_time
    for _ in range(WARMUP_CHUNKS * steps_per_chunk):
        world.step()
        world.snapshot()
    mujoco.mj_step(bare_model, bare_data, nstep=WARMUP_CHUNKS * steps_per_chunk * world.substeps)
    for first in range(0, steps, steps_per_chunk):
        count = min(steps_per_chunk, steps - first)
        start, start_cpu = clock(), cpu()
        for _ in range(count):
            world.step()
            t = cpu()
            world.snapshot()
            snapshot_s += cpu() - t
        world_chunk = clock() - start
        world_s += world_chunk
        world_cpu += cpu() - start_cpu
        start, start_cpu = clock(), cpu()
        for _ in range(count * world.substeps):
            mujoco.mj_step(bare_model, bare_data)
        bare_chunk = clock() - start
        bare_s += bare_chunk
        bare_cpu += cpu() - start_cpu
        pair_ratios.append(bare_chunk / world_chunk)
    simulated = steps * world.step_ms / 1000.0
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
        # median over the (world, bare) pairs of adjacent chunks: a burst of load that falls
        # on one chunk moves one pair, not the figure
        "ratio_pair_median": round(statistics.median(pair_ratios), 3),
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
