"""``hlvs render`` and ``hlvs bench
sim|api|stub|envs|video|bringup|delivery|cli|viewer|scrimmage|hog|runtime``: commands with
parsers of their own, to which the arguments are forwarded unread (``--help`` included).

The orchestrator does not import the simulator; ``render`` and the simulator's (or the learning
environments') benchmarks run ``python -m simulator`` (``python -m envs``) with the same
interpreter (``HLVS_PROG`` tells it to name itself ``hlvs``), so ``hlvs`` stays the one entry
point for users. ``hlvs bench bringup``, ``delivery``, ``cli`` and ``scrimmage`` are the
orchestrator's own.
"""

from __future__ import annotations

import argparse
import os
import sys
from typing import Any

from hlvs.commands.forwarding import forward

SIMULATOR_BENCHES = {
    "sim": "physics steps of the soccer world per second (JSON)",
    "api": "the robot API server: step rate and latency with clients connected (JSON)",
    "stub": "the stub robot: reach and shots on goal (JSON)",
    "video": "hlvs render: a match video's frames a second and CPU a frame (JSON)",
}


def _exec_simulator(argv: list[str], module: str = "simulator") -> int:
    os.environ["HLVS_PROG"] = "hlvs"
    os.execv(sys.executable, [sys.executable, "-m", module, *argv])
    return 0  # not reached


def register(sub: Any) -> None:
    forward(
        sub,
        "render",
        help="render a replay file to a video (offscreen)",
        func=lambda a: _exec_simulator(["render", *a.rest]),
    )
    bench: argparse.ArgumentParser = sub.add_parser(
        "bench", help="benchmarks that print JSON", description="Benchmarks that print JSON."
    )
    kinds = bench.add_subparsers(dest="bench_kind", metavar="KIND", title="benchmarks")
    kinds.required = True
    for kind, text in SIMULATOR_BENCHES.items():
        forward(
            kinds, kind, help=text,
            func=lambda a, kind=kind: _exec_simulator([kind, *a.rest], module="benchmarks"),
        )
    forward(kinds, "envs", help="the learning environments: steps per second (JSON)",
            func=_envs)
    forward(kinds, "bringup", help="time from hlvs match to the kick-off (JSON)", func=_bringup)
    forward(
        kinds, "report", help="the performance matrix (sim, async, lockstep, pipelined, "
        "cameras, bring-up, a whole match) with every ratio and its target in one JSON document",
        func=_report,
    )
    forward(kinds, "delivery", help="log delivery throughput to SFTP and S3 (JSON)",
            func=_delivery)
    forward(kinds, "cli", help="start-up time of hlvs --help (JSON)", func=_cli)
    forward(
        kinds, "pool", help="matches through the Slurm pool against the same match locally "
        "(JSON)", func=_pool,
    )
    forward(
        kinds, "models", help="physics cost per robot: team model against built-in (JSON)",
        func=_models,
    )
    forward(
        kinds, "actuators", help="catalogue servos in the simulator against their datasheets "
        "and Webots' motor model (JSON)", func=_actuators,
    )
    forward(
        kinds, "viewer", help="the web viewer: open and play a 2 x 10 min 4 v 4 replay (JSON)",
        func=_viewer,
    )
    forward(kinds, "hog",
            help="a CPU-hogging robot: the others' real-time factor against a match without "
            "it, under the admission rules (JSON)", func=_hog)
    forward(kinds, "runtime",
            help="the robots under another OCI runtime (gVisor's runsc): real-time factor and "
            "the stubs' control loop against the engine's default (JSON)", func=_runtime)
    forward(kinds, "scrimmage",
            help="K default scrimmages: halves reaching PLAYING, kicks, goals, wall time (JSON)",
            func=_scrimmage)


def _envs(args: argparse.Namespace) -> int:
    from benchmarks import envs as envs_bench  # gymnasium is imported after the arguments

    return int(envs_bench.main(list(args.rest)))


def _hog(args: argparse.Namespace) -> int:
    from benchmarks import hog as hog_bench

    return int(hog_bench.main(list(args.rest)))


def _runtime(args: argparse.Namespace) -> int:
    from benchmarks import runtime as runtime_bench

    return int(runtime_bench.main(list(args.rest)))


def _scrimmage(args: argparse.Namespace) -> int:
    from benchmarks import scrimmage as scrimmage_bench

    return int(scrimmage_bench.main(list(args.rest)))


def _report(args: argparse.Namespace) -> int:
    from benchmarks import report as report_bench

    return report_bench.main(args.rest)


def _bringup(args: argparse.Namespace) -> int:
    from benchmarks import bringup as bringup_bench

    return int(bringup_bench.main(list(args.rest)))


def _viewer(args: argparse.Namespace) -> int:
    os.environ["HLVS_PROG"] = "hlvs"
    from benchmarks import viewer as viewer_bench

    return int(viewer_bench.main(list(args.rest)))


def _pool(args: argparse.Namespace) -> int:
    os.environ["HLVS_PROG"] = "hlvs"
    from benchmarks import pool as pool_bench

    return int(pool_bench.main(list(args.rest)))


def _models(args: argparse.Namespace) -> int:
    os.environ["HLVS_PROG"] = "hlvs"
    from benchmarks import models as models_bench

    return int(models_bench.main(list(args.rest)))


def _actuators(args: argparse.Namespace) -> int:
    os.environ["HLVS_PROG"] = "hlvs"
    from benchmarks import actuators as actuators_bench

    return int(actuators_bench.main(list(args.rest)))


def _cli(args: argparse.Namespace) -> int:
    from benchmarks import cli as cli_bench

    return int(cli_bench.main(list(args.rest)))


def _delivery(args: argparse.Namespace) -> int:
    from benchmarks import delivery as delivery_bench

    return int(delivery_bench.main(list(args.rest)))
