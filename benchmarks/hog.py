"""``hlvs bench hog``: how much a robot that burns every CPU it may use slows the others.

Plays pairs of short 1 v 1 matches with ``hlvs match``, both under the admission rules (each
robot's ``limits.cpus`` chosen so that the robots plus the simulator fit this host, and the
match marked official so that it would be refused otherwise): blue is the stub robot, red 1
either idles (baseline) or forks ``--hogs`` busy processes (hog). By default the matches run as
the league's official ones: ``async`` stepping (the simulation never waits for clients) capped
at real time (``--max-rtf 1``), so the simulator's real-time factor is the speed everyone gets;
``--max-rtf 0`` lifts the cap (the raw speed, more sensitive to other load on the machine);
``--stepping lockstep`` makes every step wait for the blue stub, which then shares the robots'
CPUs with the hog. The runs alternate (baseline,
hog, baseline, hog, ...) so that other load on the machine touches both.

Prints one JSON line: the real-time factors of every run, their medians and the ratio
hog / baseline (target at least 0.9).
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
from contracts.codec import to_data
from contracts.match_results import AdmissionRecord, MatchResults

TARGET = 0.9
IDLE = "python3 -c \"import time; time.sleep(10**6)\""


def _hog_command(processes: int) -> str:
    forks = max(0, processes.bit_length() - 1)  # each fork doubles: 2**forks processes
    return ("python3 -c \"exec('import os\\nfor _ in range(" + str(forks) + "): os.fork()"
            "\\nwhile True: pass')\"")


def _play(work: Path, name: str, *, red_command: str, cpus: float, half_s: float,
          stepping: str, max_rtf: float) -> MatchResults:
    from orchestrator.project_images import project_image

    match_id = f"bench-hog-{name}-{os.getpid()}"
    folder = work / f"{name}-config"
    game = scrimmage_files(folder, match_id=match_id, half_s=half_s, stepping=stepping,
                           max_rtf=max_rtf, options=("--red-image", project_image("team-base")),
                           fields={"official": True}, limits={"cpus": cpus, "memory_gb": 1})
    team = json.loads((folder / "team_red.json").read_text())
    for entry in team["players"].values():
        entry["dockerCmd"] = red_command
    (folder / "team_red.json").write_text(json.dumps(team, indent=2))
    return play("hog", game, work / name, match_id=match_id)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="hlvs bench hog", description=__doc__.split("\n")[0])
    parser.add_argument("--pairs", type=int, default=2, help="baseline + hog pairs (default 2)")
    parser.add_argument("--hogs", type=int, default=4,
                        help="busy processes in the hogging robot (a power of 2, default 4)")
    parser.add_argument("--half-duration", type=float, default=10.0,
                        help="simulated seconds per half (default 10)")
    parser.add_argument("--stepping", choices=("async", "lockstep"), default="async",
                        help="stepping of the matches (default async, as the league)")
    parser.add_argument("--max-rtf", type=float, default=1.0,
                        help="maximum_real_time_factor of the matches (default 1, as official "
                        "matches; 0: uncapped)")
    parser.add_argument("--json", action="store_true", help="accepted; the output is JSON")
    args = parser.parse_args(argv)
    from orchestrator.match.admission import SIMULATOR_CPUS, HostResources

    host = HostResources.local()
    cpus = round(max(0.1, (host.cpus - SIMULATOR_CPUS) / 2), 2)  # two robots + the simulator
    runs: dict[str, list[float]] = {"baseline": [], "hog": []}
    stub: dict[str, list[dict[str, Any]]] = {"baseline": [], "hog": []}
    admission: AdmissionRecord | None = None
    started = time.monotonic()
    with tempfile.TemporaryDirectory(prefix="hlvs-bench-hog-") as tmp:
        for i in range(args.pairs):
            for kind, command in (("baseline", IDLE), ("hog", _hog_command(args.hogs))):
                results = _play(Path(tmp), f"{kind}{i}", red_command=command, cpus=cpus,
                                half_s=args.half_duration, stepping=args.stepping,
                                max_rtf=args.max_rtf)
                runs[kind].append(float(results.real_time_factor or 0.0))
                blue = results.robots["blue-1"].api
                p90 = (blue.get("round_trip_ms") or {}).get("p90") if blue else None
                stub[kind].append({"messages_in": blue.get("messages_in") if blue else None,
                                   "round_trip_ms_p90": p90})
                admission = results.admission
    baseline, hog = statistics.median(runs["baseline"]), statistics.median(runs["hog"])
    ratio = round(hog / baseline, 3) if baseline > 0 else 0.0
    print(json.dumps({
        "bench": "hog",
        "stepping": args.stepping,
        "maximum_real_time_factor": args.max_rtf,
        "blue_stub_api": stub,
        "host_cpus": host.cpus,
        "cpus_per_robot": cpus,
        "hog_processes": 2 ** max(0, args.hogs.bit_length() - 1),
        "admission": to_data(admission),
        "real_time_factor": {k: [round(v, 3) for v in vals] for k, vals in runs.items()},
        "median_baseline": round(baseline, 3),
        "median_hog": round(hog, 3),
        "ratio": ratio,
        "target": TARGET,
        "meets_target": ratio >= TARGET,
        "load_avg": [round(x, 2) for x in os.getloadavg()],
        "wall_s": round(time.monotonic() - started, 1),
    }, sort_keys=True))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
