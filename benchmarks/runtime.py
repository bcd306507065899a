"""``hlvs bench runtime``: what running the robots under another OCI runtime costs (gVisor's
``runsc``, ``limits.robot_runtime``; configs/README.md).

Plays pairs of short 1 v 1 matches of the project's stub robots with ``hlvs match``, the same
match but for the robots' runtime: the engine's default (runc) and ``--runtime``, alternating
(default, other, default, other, ...) so that other load on the machine touches both. By
default the matches step in ``lockstep`` uncapped (``--max-rtf 0``): every step waits for both
robots, so the real-time factor is the speed of the robots' control loops through the robot
API, where gVisor's cost (every system call and every packet through its own kernel) shows;
``--stepping async`` measures the simulator alone beside the robots.

Prints one JSON line: per runtime, each run's real-time factor and the stubs' control loop as
the simulator saw it (round trip p50 / p90 in ms: from a sensor message sent to the robot's
answer; messages per simulated second), their medians, and the ratios other / default.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import tempfile
import time
from pathlib import Path
from typing import Any

from benchmarks.short_match import play, scrimmage_files
from contracts.match_results import MatchResults


def _play(work: Path, name: str, *, runtime: str, half_s: float, stepping: str,
          max_rtf: float) -> MatchResults:
    match_id = f"bench-runtime-{name}-{os.getpid()}"
    game = scrimmage_files(work / f"{name}-config", match_id=match_id, half_s=half_s,
                           stepping=stepping, max_rtf=max_rtf, limits={"robot_runtime": runtime})
    return play("runtime", game, work / name, match_id=match_id, match_args=("--gpu", "off"))


def _loop(results: MatchResults) -> dict[str, Any]:
    """The stubs' control loops as the simulator measured them (both robots pooled: the
    median of their p50 and p90 round trips, messages per simulated second)."""
    sim_s = (results.sim_time_ms or 0) / 1000.0
    p50, p90, rate = [], [], []
    for robot in results.robots.values():
        api: dict[str, Any] = dict(robot.api or {})
        trip: dict[str, Any] = dict(api.get("round_trip_ms") or {})
        if trip.get("p50") is not None:
            p50.append(float(trip["p50"]))
            p90.append(float(trip["p90"]))
        if sim_s > 0:
            rate.append(float(api.get("messages_in") or 0) / sim_s)
    return {
        "round_trip_ms_p50": round(statistics.median(p50), 3) if p50 else None,
        "round_trip_ms_p90": round(statistics.median(p90), 3) if p90 else None,
        "messages_per_sim_s": round(statistics.median(rate), 1) if rate else None,
    }


def _ratio(other: float | None, default: float | None) -> float | None:
    return round(other / default, 3) if other is not None and default else None


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="hlvs bench runtime",
                                     description=__doc__.split("\n")[0])
    parser.add_argument("--runtime", default="runsc",
                        help="the robots' runtime measured against the engine's default "
                        "(default runsc: gVisor)")
    parser.add_argument("--pairs", type=int, default=2, help="default + other pairs (default 2)")
    parser.add_argument("--half-duration", type=float, default=10.0,
                        help="simulated seconds per half (default 10)")
    parser.add_argument("--stepping", choices=("lockstep", "async"), default="lockstep",
                        help="stepping of the matches (default lockstep: the robots' loops set "
                        "the pace)")
    parser.add_argument("--max-rtf", type=float, default=0.0,
                        help="maximum_real_time_factor (default 0: uncapped)")
    parser.add_argument("--json", action="store_true", help="accepted; the output is JSON")
    args = parser.parse_args(argv)
    from orchestrator.engine import connect, engine_endpoint, engine_runtimes

    known = engine_runtimes(connect())
    if args.runtime not in known:
        raise SystemExit(f"hlvs bench runtime: the Docker engine at {engine_endpoint()} has no "
                         f"runtime {args.runtime!r} (it has: {', '.join(known)}; see "
                         "configs/README.md)")
    kinds = {"default": "", args.runtime: args.runtime}
    rtf: dict[str, list[float]] = {k: [] for k in kinds}
    loops: dict[str, list[dict[str, Any]]] = {k: [] for k in kinds}
    started = time.monotonic()
    with tempfile.TemporaryDirectory(prefix="hlvs-bench-runtime-") as tmp:
        for i in range(args.pairs):
            for kind, runtime in kinds.items():
                results = _play(Path(tmp), f"{kind}{i}", runtime=runtime,
                                half_s=args.half_duration, stepping=args.stepping,
                                max_rtf=args.max_rtf)
                rtf[kind].append(float(results.real_time_factor or 0.0))
                loops[kind].append(_loop(results))

    def median(kind: str, key: str) -> float | None:
        found = [run[key] for run in loops[kind] if run[key] is not None]
        return round(statistics.median(found), 3) if found else None

    medians = {kind: {"real_time_factor": round(statistics.median(rtf[kind]), 3),
                      **{key: median(kind, key) for key in loops[kind][0]}} for kind in kinds}
    other, default = medians[args.runtime], medians["default"]
    print(json.dumps({
        "bench": "runtime",
        "runtime": args.runtime,
        "stepping": args.stepping,
        "maximum_real_time_factor": args.max_rtf,
        "real_time_factor": {k: [round(v, 3) for v in vals] for k, vals in rtf.items()},
        "control_loop": loops,
        "medians": medians,
        "ratio": {key: _ratio(other[key], default[key]) for key in default},
        "load_avg": [round(x, 2) for x in os.getloadavg()],
        "wall_s": round(time.monotonic() - started, 1),
    }, sort_keys=True))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
