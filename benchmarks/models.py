"""``hlvs bench models``: physics cost per robot of a team robot model against the built-in one,
with the same number of robots, in the same run.

Builds three worlds on the kid field: no robots (the field and the ball), ``--robots`` built-in
``kid-default`` robots, and ``--robots`` robots of the team model (default: the Wolfgang example
package), every robot standing in its pose under position control, and times ``--steps`` world
steps of each, ``--repeats`` times, interleaved. The cost per robot is the world's step time
minus the empty world's, divided by the number of robots (medians). Also times what a match
start pays for the model before the first step: loading the package (``load_s``, once per
process) and the model check of the team file (``check_s``: the rule book's measurements and
physics checks, run on every match start). Prints one JSON line.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import statistics
import time
from pathlib import Path
from typing import Any

from orchestrator.paths import user_path

EXAMPLE = Path(__file__).resolve().parents[1] / "configs" / "examples" / "robots" / "wolfgang"


def _world(model: str | None, robots: int) -> Any:
    from contracts.ids import RobotId, TeamColor
    from simulator.world import RobotPlacement, World

    placements = []
    for i in range(robots if model else 0):
        team = TeamColor.RED if i % 2 == 0 else TeamColor.BLUE
        sign = -1.0 if team is TeamColor.RED else 1.0
        placements.append(
            RobotPlacement(
                id=RobotId(team, i // 2 + 1),
                model=model or "kid-default",
                x_m=sign * (1.0 + i // 2),
                y_m=-1.5 + (i // 2),
                yaw_rad=0.0 if sign < 0 else math.pi,
            )
        )
    return World.create(field_class="kid", robots=placements, seed=1)


def _check_cost(folder: Path) -> tuple[float, float]:
    """Seconds to load the model package (first time in this process) and to check it."""
    from simulator.world.robots.team import check, load_team_model

    start = time.perf_counter()
    robot = load_team_model(folder)
    loaded = time.perf_counter()
    check(robot, official=True)
    return loaded - start, time.perf_counter() - loaded


def _time_steps(world: Any, steps: int) -> float:
    start = time.perf_counter()
    for _ in range(steps):
        world.step()
    return (time.perf_counter() - start) / steps


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog=f"{os.environ.get('HLVS_PROG', 'python -m benchmarks.models')} bench models",
        description=__doc__.split("\n\n")[0] if __doc__ else None,
    )
    parser.add_argument("--robots", type=int, default=8, help="robots per world (default 8)")
    parser.add_argument(
        "--model",
        type=user_path,
        default=EXAMPLE,
        help="team robot model package (default: the Wolfgang example)",
    )
    parser.add_argument(
        "--steps",
        type=int,
        default=500,
        help="world steps (8 ms each) timed per repeat (default 500)",
    )
    parser.add_argument("--repeats", type=int, default=5, help="timed repeats (default 5)")
    parser.add_argument("--json", action="store_true", help="accepted: the output is JSON")
    args = parser.parse_args(argv)
    load_s, check_s = _check_cost(args.model.resolve())
    worlds = {
        "empty": _world(None, 0),
        "built_in": _world("kid-default", args.robots),
        "team": _world(str(args.model.resolve()), args.robots),
    }
    for world in worlds.values():
        _time_steps(world, 50)  # warm-up: contacts settle, caches fill
    samples: dict[str, list[float]] = {name: [] for name in worlds}
    for _ in range(args.repeats):
        for name, world in worlds.items():
            samples[name].append(_time_steps(world, args.steps))
    step_s = {name: statistics.median(values) for name, values in samples.items()}
    per_robot_us = {
        name: (step_s[name] - step_s["empty"]) / args.robots * 1e6 for name in ("built_in", "team")
    }
    fallen = sum(r.fallen for r in worlds["team"].snapshot().robots)
    result = {
        "bench": "models",
        "robots": args.robots,
        "team_model": str(args.model),
        "steps": args.steps,
        "repeats": args.repeats,
        "step_ms": {name: round(value * 1e3, 4) for name, value in step_s.items()},
        "per_robot_step_us": {name: round(value, 1) for name, value in per_robot_us.items()},
        "team_over_built_in": round(per_robot_us["team"] / per_robot_us["built_in"], 3),
        "team_geoms_per_robot": int(
            sum(
                1
                for g in range(worlds["team"].model.ngeom)
                if worlds["team"].model.geom(g).name.startswith("red_1/")
            )
        ),
        "team_robots_fallen_at_end": fallen,
        "load_s": round(load_s, 3),
        "check_s": round(check_s, 3),
    }
    print(json.dumps(result))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
