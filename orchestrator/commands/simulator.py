"""``hlvs render`` and ``hlvs bench sim|api|stub|envs``: run the simulator's (or the learning
environments') own commands.

The orchestrator does not import the simulator; these commands run ``python -m simulator`` in a
child process with the same interpreter, so ``hlvs`` stays the one entry point for users.
``hlvs bench bringup`` and ``hlvs bench delivery`` are the orchestrator's own benchmarks.
"""

from __future__ import annotations

import argparse
import os
import sys
from typing import Any

SIMULATOR_BENCHES = ("sim", "api", "stub")


def _exec_simulator(argv: list[str], module: str = "simulator") -> int:
    os.execv(sys.executable, [sys.executable, "-m", module, *argv])
    return 0  # not reached


def register(sub: Any) -> None:
    render = sub.add_parser("render", help="render a replay file to a video (offscreen)")
    render.add_argument("replay")
    render.add_argument("-o", "--output", required=True)
    render.add_argument("rest", nargs=argparse.REMAINDER)
    render.set_defaults(
        func=lambda a: _exec_simulator(["render", a.replay, "-o", a.output, *a.rest])
    )

    bench = sub.add_parser(
        "bench",
        help="benchmarks that print JSON: sim, api, stub, envs, bringup, delivery",
        add_help=False,
    )
    bench.add_argument("kind", choices=(*SIMULATOR_BENCHES, "envs", "bringup", "delivery"))
    bench.add_argument("rest", nargs=argparse.REMAINDER)
    bench.set_defaults(func=_bench)


def _bench(args: argparse.Namespace) -> int:
    if args.kind in SIMULATOR_BENCHES:
        return _exec_simulator(["bench", args.kind, *args.rest])
    if args.kind == "envs":  # the learning environments' package
        return _exec_simulator(["bench", *args.rest], module="envs")
    if args.kind == "delivery":
        from orchestrator.delivery.bench import main as delivery_main

        return int(delivery_main(list(args.rest)))
    from orchestrator.bringup import main as bringup_main

    return int(bringup_main(list(args.rest)))
