"""``python -m benchmarks stub``: can the stub striker find, reach and kick the ball?

In-process world (no network), one kid-default striker 2 m from the ball at a random (seeded)
bearing and heading. The striker runs the same controller as in a match: it sees only its joint
angles, IMU and head camera (320x240 rendered every 96 ms; colour blob detector), and knows its
starting pose (as a team knows its starting pose from its team file). A trial succeeds when the
striker kicks within the time limit and the ball travels at least 0.5 m. Prints one JSON line.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time
from typing import TYPE_CHECKING, TypedDict

if TYPE_CHECKING:  # numpy and the world are imported after the arguments (fast --help)
    from testkit.stub_world import ReachResult, ShotResult


class ReachSummary(TypedDict):
    """``hlvs bench stub`` (reach): the stub walking to the ball and kicking it."""

    bench: str
    model: str
    trials: int
    successes: int
    success_rate: float
    mean_kick_distance_m: float | None
    mean_time_to_kick_s: float | None
    falls_per_min: float
    sim_time_s: float
    wall_time_s: float
    seed: int
    perception: str  # what the stub sees with


class ShotsSummary(TypedDict):
    """``hlvs bench stub --scenario shots``: shots on goal (against a goalie with --goalie)."""

    bench: str
    scenario: str
    model: str
    goalie: bool
    trials: int
    goals: int
    goal_rate: float
    outcomes: list[str]
    mean_time_to_goal_s: float | None
    kicks: int
    falls_per_min: float
    sim_time_s: float
    wall_time_s: float
    seed: int


def summarize(results: list[ReachResult], *, seed: int, wall_s: float) -> ReachSummary:
    kicks = [r.kick_distance_m for r in results if r.success]
    times = [r.time_to_kick_s for r in results if r.success and r.time_to_kick_s is not None]
    sim_s = sum(r.sim_time_s for r in results)
    return {
        "bench": "stub",
        "model": "kid-default",
        "trials": len(results),
        "successes": sum(r.success for r in results),
        "success_rate": round(sum(r.success for r in results) / max(len(results), 1), 3),
        "mean_kick_distance_m": round(sum(kicks) / len(kicks), 3) if kicks else None,
        "mean_time_to_kick_s": round(sum(times) / len(times), 2) if times else None,
        "falls_per_min": round(sum(r.falls for r in results) / (sim_s / 60.0), 3) if sim_s else 0,
        "sim_time_s": round(sim_s, 1),
        "wall_time_s": round(wall_s, 1),
        "seed": seed,
        "perception": (
            "head camera 320x240 every 96 ms, white+black ball blob detector, "
            "ground projection from joint angles and IMU; pose from the known start pose, "
            "gait odometry and gyro; no ground truth"
        ),
    }


def main(argv: list[str]) -> int:
    program = os.environ.get("HLVS_PROG", "python -m simulator")
    parser = argparse.ArgumentParser(prog=f"{program} bench stub")
    parser.add_argument("--trials", type=int, default=10, help="trials to run (default 10)")
    parser.add_argument("--seed", type=int, default=1, help="seed of the first trial (default 1)")
    parser.add_argument(
        "--distance-m",
        type=float,
        default=2.0,
        help="reach: start distance to the ball in metres (default 2)",
    )
    parser.add_argument(
        "--time-limit-s", type=float, default=60.0, help="simulated seconds per trial (default 60)"
    )
    parser.add_argument(
        "--scenario",
        choices=("reach", "shots"),
        default="reach",
        help="reach the ball, or shots on goal (default reach)",
    )
    parser.add_argument("--goalie", action="store_true", help="shots: an opponent goalie defends")
    parser.add_argument("--json", action="store_true", help="only the JSON line")
    args = parser.parse_args(argv)
    if args.trials < 1:
        print("--trials: expected an integer >= 1", file=sys.stderr)
        return 2
    os.environ.setdefault("MUJOCO_GL", "osmesa")
    os.environ.setdefault("PYOPENGL_PLATFORM", os.environ["MUJOCO_GL"])
    start = time.perf_counter()
    if args.scenario == "shots":
        return _shots(args, start)
    from testkit.stub_world import run_reach

    results = []
    for trial in range(args.trials):
        result = run_reach(
            seed=args.seed * 1000 + trial,
            distance_m=args.distance_m,
            time_limit_s=args.time_limit_s,
        )
        results.append(result)
        if not args.json:
            print(f"trial {trial}: {result}", file=sys.stderr)
    print(json.dumps(summarize(results, seed=args.seed, wall_s=time.perf_counter() - start)))
    return 0


def _shots(args: argparse.Namespace, start: float) -> int:
    from testkit.stub_world import run_shot

    shots = []
    for trial in range(args.trials):
        shot = run_shot(
            seed=args.seed * 1000 + trial, time_limit_s=args.time_limit_s, goalie=args.goalie
        )
        shots.append(shot)
        if not args.json:
            print(f"trial {trial}: {shot}", file=sys.stderr)
    summary = summarize_shots(
        shots, seed=args.seed, goalie=args.goalie, wall_s=time.perf_counter() - start
    )
    print(json.dumps(summary))
    return 0


def summarize_shots(
    results: list[ShotResult], *, seed: int, goalie: bool, wall_s: float
) -> ShotsSummary:
    goals = [r for r in results if r.goal]
    times = [r.time_to_goal_s for r in goals if r.time_to_goal_s is not None]
    sim_s = sum(r.sim_time_s for r in results)
    return {
        "bench": "stub",
        "scenario": "shots",
        "model": "kid-default",
        "goalie": goalie,
        "trials": len(results),
        "goals": len(goals),
        "goal_rate": round(len(goals) / max(len(results), 1), 3),
        "outcomes": [r.outcome for r in results],
        "mean_time_to_goal_s": round(sum(times) / len(times), 2) if times else None,
        "kicks": sum(r.kicks for r in results),
        "falls_per_min": round(sum(r.falls for r in results) / (sim_s / 60.0), 3) if sim_s else 0,
        "sim_time_s": round(sim_s, 1),
        "wall_time_s": round(wall_s, 1),
        "seed": seed,
    }
