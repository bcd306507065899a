"""``hlvs bench cli``: wall time of ``hlvs --help`` (and of each command's ``--help``) in a fresh
interpreter, as a user types it. Prints one JSON line; the target is 0.5 s for ``hlvs --help``.
``python_median_s`` is a bare ``python -c pass`` on the same machine at the same time, so that a
loaded machine shows as such (``help_over_python_s`` is what hlvs adds)."""

from __future__ import annotations

import argparse
import json
import os
import shutil
import statistics
import subprocess
import sys
import time
from collections.abc import Sequence

TARGET_S = 0.5


def _command() -> list[str]:
    script = os.path.join(os.path.dirname(sys.executable), "hlvs")
    if os.path.exists(script):
        return [script]
    found = shutil.which("hlvs")
    return [found] if found else [sys.executable, "-m", "hlvs"]


def time_help(args: Sequence[str], *, runs: int) -> list[float]:
    """Seconds of ``hlvs ARGS --help`` for each of ``runs`` runs (exit 0 checked)."""
    times = []
    for _ in range(runs):
        started = time.perf_counter()
        done = subprocess.run(
            [*_command(), *args, "--help"], capture_output=True, text=True, check=False
        )
        times.append(time.perf_counter() - started)
        if done.returncode != 0:
            raise SystemExit(f"hlvs {' '.join(args)} --help exited {done.returncode}")
    return times


def time_python(*, runs: int) -> list[float]:
    """Seconds of a bare ``python -c pass`` (the interpreter's own start-up)."""
    times = []
    for _ in range(runs):
        started = time.perf_counter()
        subprocess.run([sys.executable, "-c", "pass"], check=True)
        times.append(time.perf_counter() - started)
    return times


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="hlvs bench cli", description=__doc__)
    parser.add_argument("--runs", type=int, default=10, help="runs of each command (default 10)")
    parser.add_argument(
        "--command", action="append", default=[], metavar="WORDS",
        help="also time 'hlvs WORDS --help' (repeatable, e.g. --command 'images pull')",
    )
    parser.add_argument("--json", action="store_true", help="print only the JSON line")
    args = parser.parse_args(argv)
    if args.runs < 1:
        parser.error("--runs: expected an integer >= 1")
    top = time_help([], runs=args.runs)
    bare = time_python(runs=args.runs)
    result: dict[str, object] = {
        "bench": "cli",
        "runs": args.runs,
        "help_median_s": round(statistics.median(top), 4),
        "help_max_s": round(max(top), 4),
        "python_median_s": round(statistics.median(bare), 4),
        "help_over_python_s": round(statistics.median(top) - statistics.median(bare), 4),
        "target_s": TARGET_S,
        "ok": statistics.median(top) < TARGET_S,
    }
    commands = {}
    for words in args.command:
        times = time_help(words.split(), runs=args.runs)
        commands[words] = round(statistics.median(times), 4)
    if commands:
        result["commands_median_s"] = commands
    if not args.json:
        print(f"hlvs --help: median {result['help_median_s']} s over {args.runs} runs",
              file=sys.stderr)
    print(json.dumps(result, sort_keys=True))
    return 0


__all__ = ["main", "time_help", "time_python"]
