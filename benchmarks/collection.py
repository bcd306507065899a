"""Collection benchmark: copying one robot's ordinary ``/robocup-logs`` out of its folder.

``python -m benchmarks.collection [--files 300] [--mb 100] [--runs 5] [--compare-with CHECKOUT]
--json`` writes a log folder of ``--files`` files (text-like data, sizes from a few kB to a few
MB, in nested folders), copies it ``--runs`` times with
:func:`orchestrator.match.safecopy.copy_tree` and prints one JSON line: median seconds, MB/s and
files/s. With ``--compare-with`` the ``safecopy`` module of another checkout of the project is
timed in the same run, alternating with this one (``baseline`` in the JSON, and the ratio).
"""

from __future__ import annotations

import argparse
import importlib.util
import json
import random
import shutil
import statistics
import sys
import tempfile
import time
from collections.abc import Callable, Sequence
from pathlib import Path
from types import ModuleType
from typing import Any

__all__ = ["main"]


def _write_logs(root: Path, *, files: int, total_mb: float, seed: int = 7) -> int:
    """Files of mixed sizes (a long tail of large ones) adding up to about ``total_mb``."""
    rng = random.Random(seed)
    weights = [rng.paretovariate(1.2) for _ in range(files)]
    scale = total_mb * 1e6 / sum(weights)
    line = b"".join(b"%06d t=%.3f joint=%s value=%.6f\n" % (
        i, i * 0.008, b"HeadYaw", rng.random()) for i in range(2000))
    written = 0
    for index, weight in enumerate(weights):
        folder = root / f"run{index % 7}" / f"part{index % 3}"
        folder.mkdir(parents=True, exist_ok=True)
        size = max(200, int(weight * scale))
        data = (line * (size // len(line) + 1))[:size]
        (folder / f"log{index:04d}.txt").write_bytes(data)
        written += size
    return written


def _load(checkout: Path) -> ModuleType:
    path = checkout / "orchestrator" / "match" / "safecopy.py"
    spec = importlib.util.spec_from_file_location("baseline_safecopy", path)
    if spec is None or spec.loader is None:
        raise SystemExit(f"--compare-with: no {path}")
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module  # dataclasses look their module up
    spec.loader.exec_module(module)
    return module


def _time(copy: Callable[[Path, Path], Any], source: Path, work: Path) -> float:
    target = work / "out"
    shutil.rmtree(target, ignore_errors=True)
    started = time.perf_counter()
    copy(source, target)
    elapsed = time.perf_counter() - started
    shutil.rmtree(target, ignore_errors=True)
    return elapsed


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m benchmarks.collection", description=__doc__)
    parser.add_argument("--files", type=int, default=300, help="files in the folder (300)")
    parser.add_argument("--mb", type=float, default=100.0, help="total megabytes (100)")
    parser.add_argument("--runs", type=int, default=5, help="copies timed (5)")
    parser.add_argument("--compare-with", type=Path, metavar="CHECKOUT",
                        help="also time the safecopy module of this checkout of the project")
    parser.add_argument("--json", action="store_true", help="print one JSON line only")
    args = parser.parse_args(argv)
    if args.files < 1 or args.runs < 1 or args.mb <= 0:
        parser.error("--files and --runs: at least 1; --mb: above 0")
    from orchestrator.match import safecopy

    baseline = _load(args.compare_with) if args.compare_with else None
    with tempfile.TemporaryDirectory(prefix="hlvs-collection-bench-") as tmp:
        work = Path(tmp)
        source = work / "robocup-logs"
        total = _write_logs(source, files=args.files, total_mb=args.mb)
        ours: list[float] = []
        theirs: list[float] = []
        for _ in range(args.runs):
            ours.append(_time(safecopy.copy_tree, source, work))
            if baseline is not None:
                theirs.append(_time(baseline.copy_tree, source, work))
    median = statistics.median(ours)
    result: dict[str, Any] = {
        "bench": "collection", "files": args.files, "bytes": total, "runs": args.runs,
        "median_s": round(median, 4), "mb_s": round(total / 1e6 / median, 1),
        "files_s": round(args.files / median, 1),
    }
    if baseline is not None:
        base = statistics.median(theirs)
        result["baseline"] = {"checkout": str(args.compare_with), "median_s": round(base, 4),
                              "mb_s": round(total / 1e6 / base, 1)}
        result["time_ratio"] = round(median / base, 3)
    print(json.dumps(result) if args.json else json.dumps(result, indent=2))
    return 0


if __name__ == "__main__":
    sys.exit(main())
