"""`hlvs pool up|down|status`: the Slurm cluster matches can run on.

``up`` installs (Debian, as root) and starts a cluster on this machine: a controller, the
accounting daemon with MariaDB and five nodes, each in its own network namespace with its own
address (``scripts/ensure-slurm.sh``); ``down`` stops it. ``status`` lists the match jobs with
the reason each waits and its expected start, as Slurm gives them, and the nodes with their
state (and why one is drained or down) and the match on each.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
from pathlib import Path
from typing import Any

from orchestrator import ExitCode

SCRIPT = Path(__file__).resolve().parents[2] / "scripts" / "ensure-slurm.sh"
DEFAULT_CONF = "/var/lib/hlvs/slurm/slurm.conf"


def register(sub: Any) -> None:
    parser: argparse.ArgumentParser = sub.add_parser(
        "pool", help="the Slurm cluster matches run on: start it, stop it, its queue",
        description=__doc__.split("\n\n")[0] if __doc__ else None,
    )
    actions = parser.add_subparsers(dest="pool_action", metavar="ACTION", title="actions")
    actions.required = True
    up = actions.add_parser("up", help="install and start a cluster of nodes on this machine")
    up.add_argument("--nodes", type=int, default=5, help="nodes to start (default 5)")
    up.set_defaults(func=_up)
    down = actions.add_parser("down", help="stop the cluster started by 'hlvs pool up'")
    down.set_defaults(func=_down)
    status = actions.add_parser(
        "status", help="match jobs (state, reason, expected start) and the nodes (state, "
        "reason, the match on each)")
    status.add_argument("--json", action="store_true", help="one JSON document")
    status.add_argument("--slurm-conf", default=os.environ.get("SLURM_CONF", DEFAULT_CONF),
                        help="the cluster's slurm.conf (default: $SLURM_CONF or the one "
                        "'hlvs pool up' writes)")
    status.set_defaults(func=_status)


def _script(action: str, nodes: int | None = None) -> int:
    env = dict(os.environ)
    if nodes is not None:
        env["HLVS_SLURM_NODES"] = str(nodes)
    result = subprocess.run(["bash", str(SCRIPT), action], env=env, check=False)
    return ExitCode.OK if result.returncode == 0 else ExitCode.INFRASTRUCTURE


def _up(args: argparse.Namespace) -> int:
    return _script("up", args.nodes)


def _down(args: argparse.Namespace) -> int:
    return _script("down")


def _status(args: argparse.Namespace) -> int:
    from cluster import SlurmPool

    pool = SlurmPool(slurm_conf=args.slurm_conf)
    entries = pool.queue()
    nodes = pool.nodes()
    if args.json:
        print(json.dumps({"jobs": [e.to_json() for e in entries],
                          "nodes": [n.to_json() for n in nodes]}, indent=2))
        return ExitCode.OK
    if not entries:
        print("no match jobs in the cluster")
    for e in entries:
        what = e.name.removeprefix("hlvs-") if e.kind == "match" else f"({e.kind}) {e.name}"
        print(f"{e.job_id:>6} {what:<24} {e.account:<12} "
              f"{e.state:<10} {e.reason:<20} {e.expected_start} {e.nodes}")
    for n in nodes:
        jobs = ", ".join(f"{j.match_id or 'job'} ({j.job_id})" for j in n.jobs) or "-"
        print(f"node {n.name:<8} {n.state:<12} {n.cpus_allocated}/{n.cpus} CPUs  {jobs}"
              + (f"  reason: {n.reason}" if n.reason else ""))
    return ExitCode.OK
