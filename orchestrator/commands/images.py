"""``hlvs images build [--base IMAGE] [--json]``: build project images whose inputs changed.

Prints one line per image (tag, size, rebuilt or cached), or one JSON object with ``--json``.
"""

from __future__ import annotations

import argparse
import json
import time
from typing import Any


def register(sub: Any) -> None:
    parser: argparse.ArgumentParser = sub.add_parser(
        "images", help="build the simulator, stub and team-base images (content-tagged)"
    )
    actions = parser.add_subparsers(dest="images_action", metavar="ACTION")
    actions.required = True
    build = actions.add_parser("build", help="build every project image whose inputs changed")
    build.add_argument(
        "--base",
        metavar="IMAGE",
        help="base image with Python 3.11 (e.g. python:3.11-slim); "
        "default: a Debian bookworm base made locally with debootstrap",
    )
    build.add_argument("--json", action="store_true", help="print one JSON object")
    build.set_defaults(func=_build)


def _build(args: argparse.Namespace) -> int:
    from orchestrator.images import build_all

    started = time.monotonic()
    built = build_all(base=args.base)
    total_s = time.monotonic() - started
    if args.json:
        print(
            json.dumps(
                {"images": [b.as_json() for b in built], "seconds": round(total_s, 2)},
                sort_keys=True,
            )
        )
        return 0
    for image in built:
        state = "rebuilt" if image.rebuilt else "cached"
        print(f"{image.reference}  {image.size_bytes / 1e6:8.1f} MB  {state}")
    print(f"images ready in {total_s:.1f} s")
    return 0
