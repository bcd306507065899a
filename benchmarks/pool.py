"""``hlvs bench pool``: matches through the Slurm pool against the same match run locally.

Starts the one-machine cluster if needed (``scripts/ensure-slurm.sh up``, root on Debian), plays
one short stub scrimmage locally (``hlvs match`` on this host) and then ``--matches`` of the same
scrimmage through the Slurm pool, submitted at once, and reports: every match's outcome, the
wall time of the whole batch, submit-to-start latency percentiles (Slurm's SubmitTime and
StartTime), and the pool's overhead: a match's wall time through the pool (submit to report)
over the local match's wall time, median over the pool's matches. With more matches than nodes
the later ones wait for a node, so the overhead is computed over the first ``--nodes``
matches only. ``--placement league`` plays 2 v 2 scrimmages, each with the simulator and every
robot on a node of its own (five nodes per match; the local match is the same 2 v 2 on this
host). Prints one JSON line.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from datetime import datetime
from pathlib import Path
from typing import Any

from contracts import files
from contracts.errors import ContractError
from contracts.match_results import MatchReport

ROOT = Path(__file__).resolve().parents[1]
CONF = "/var/lib/hlvs/slurm/slurm.conf"


def _job(folder: Path, name: str, half_s: float, *, league: bool = False) -> Any:
    from cluster import MatchJob
    from orchestrator.match.scrimmage import ScrimmageRequest, write_files
    from orchestrator.project_images import project_image

    args = argparse.Namespace(
        red_image=None,
        blue_image=None,
        players=2 if league else 1,
        half_duration=half_s,
        minimum_play=0.0,  # the pool's overhead is measured, not football
        wait_before_ready=1.0,
        grace=2.0,
        robot_command=None,
        match_id=f"bench-{name}-{os.getpid()}",
        seed=5,
    )
    game = write_files(ScrimmageRequest.from_options(args), folder / name / "config",
                       stub_image=project_image("stub"))
    return MatchJob(match_id=args.match_id, game_path=game, work_dir=folder / name,
                    robot_nodes=4 if league else 0)


def _status(out: Path) -> str:
    try:
        return MatchReport.load(out / files.REPORT).status
    except ContractError:
        return "no report"


def _sacct_times(job_id: str) -> tuple[float, float] | None:
    text = subprocess.run(
        ["sacct", "-n", "-X", "-P", "-j", job_id, "-o", "Submit,Start"],
        capture_output=True,
        text=True,
        env={**os.environ, "SLURM_CONF": CONF},
        check=False,
    ).stdout.strip()
    try:
        submit, start = text.splitlines()[0].split("|")
        return (
            datetime.fromisoformat(submit).timestamp(),
            datetime.fromisoformat(start).timestamp(),
        )
    except (IndexError, ValueError):
        return None


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog=f"{os.environ.get('HLVS_PROG', 'python -m benchmarks.pool')} bench pool",
        description=__doc__.split("\n\n")[0] if __doc__ else None,
    )
    parser.add_argument("--nodes", type=int, default=5, help="cluster nodes (default 5)")
    parser.add_argument(
        "--matches", type=int, default=3, help="matches through the pool (default 3)"
    )
    parser.add_argument(
        "--half-duration",
        type=float,
        default=4.0,
        help="simulated seconds per half of each scrimmage (default 4)",
    )
    parser.add_argument(
        "--placement",
        choices=("dense", "league"),
        default="dense",
        help="dense (default): a 1 v 1 on one node per match; league: a 2 v 2 with the "
        "simulator and each robot on a node of its own",
    )
    parser.add_argument("--json", action="store_true", help="accepted: the output is JSON")
    args = parser.parse_args(argv)
    from cluster import JobState
    from cluster.slurm import SlurmPool

    up = subprocess.run(
        ["bash", str(ROOT / "scripts" / "ensure-slurm.sh"), "up"],
        env={**os.environ, "HLVS_SLURM_NODES": str(args.nodes)},
        capture_output=True,
        text=True,
        check=False,
    )
    if up.returncode != 0:
        print(json.dumps({"bench": "pool", "error": up.stderr[-500:] or up.stdout[-500:]}))
        return 3
    with tempfile.TemporaryDirectory(prefix="hlvs-bench-pool-") as tmp:
        folder = Path(tmp)
        league = args.placement == "league"
        local = _job(folder, "local", args.half_duration, league=league)
        started = time.monotonic()
        subprocess.run(
            [
                sys.executable,
                "-m",
                "hlvs",
                "-q",
                "match",
                str(local.game_path),
                "--out",
                str(local.work_dir / "out"),
            ],
            capture_output=True,
            check=False,
        )
        local_s = time.monotonic() - started
        pool = SlurmPool(slurm_conf=CONF, host_network=True, slots=args.nodes)
        jobs = [_job(folder, f"p{i}", args.half_duration, league=league)
                for i in range(args.matches)]
        at_once = max(1, args.nodes // 5) if league else args.nodes  # matches side by side
        batch_start = time.monotonic()
        handles = [pool.submit(job) for job in jobs]
        ended: dict[str, float] = {}
        while len(ended) < len(handles):
            for handle in handles:
                if handle not in ended and pool.status(handle).state in (
                    JobState.FINISHED,
                    JobState.LOST,
                ):
                    ended[handle] = time.monotonic() - batch_start
            time.sleep(0.5)
        wall_s = time.monotonic() - batch_start
        latencies = []
        for handle in handles:
            times = _sacct_times(handle.split(":")[1])
            if times is not None:
                latencies.append(times[1] - times[0])
        first = sorted(ended[h] for h in handles)[:at_once]
        outcomes = [_status(pool.results_dir(h)) for h in handles]
        result = {
            "bench": "pool",
            "nodes": args.nodes,
            "placement": args.placement,
            "matches": args.matches,
            "completed": sum(1 for o in outcomes if o == "success"),
            "outcomes": outcomes,
            "local_match_s": round(local_s, 1),
            "local_outcome": _status(local.work_dir / "out"),
            "wall_s": round(wall_s, 1),
            "submit_to_start_s": {
                "p50": round(statistics.median(latencies), 2) if latencies else None,
                "p90": round(sorted(latencies)[int(0.9 * (len(latencies) - 1))], 2)
                if latencies
                else None,
                "max": round(max(latencies), 2) if latencies else None,
            },
            "overhead": round(statistics.median(first) / local_s, 3),
            "load_average": [round(x, 1) for x in os.getloadavg()],
        }
    print(json.dumps(result))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
