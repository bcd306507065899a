"""``hlvs images build|pull``: the project images, and a team's images before a match.

``build [--base IMAGE] [--json]`` builds project images whose inputs changed and prints one line
per image (tag, size, rebuilt or cached). ``pull TEAM_CONFIG [--image-limit-gb GB] [--json]``
checks every player's image in its registry (login, tag, size, the team's total with each layer
once), pulls it with retries and a progress bar, pins it by digest and checks its size, as the
runner does before a match; it exits 1 when a player has no usable image, 3 when every image
that failed did so for a reason of the infrastructure (registry unreachable, a 5xx answer, a
broken connection: trying again later may work).
"""

from __future__ import annotations

import argparse
import json
import time
from collections.abc import Iterable
from typing import TYPE_CHECKING, Any

from orchestrator import ExitCode, user_path

if TYPE_CHECKING:
    from orchestrator import ImageError


def register(sub: Any) -> None:
    parser: argparse.ArgumentParser = sub.add_parser(
        "images", help="build the project images; pull and check a team's images"
    )
    actions = parser.add_subparsers(dest="images_action", metavar="ACTION")
    actions.required = True
    build = actions.add_parser("build", help="build every project image whose inputs changed")
    build.add_argument(
        "--base",
        metavar="IMAGE",
        help="base image with Python 3.11 (e.g. python:3.11-slim); "
        "default: a Debian bookworm base made locally with mmdebstrap",
    )
    build.add_argument("--json", action="store_true", help="print one JSON object")
    build.set_defaults(func=_build)
    pull = actions.add_parser(
        "pull", help="pull and pin a team's images as a match would (reports each player)"
    )
    pull.add_argument("team_config", type=user_path, help="team_config.json")
    pull.add_argument(
        "--image-limit-gb", type=float, default=10.0, metavar="GB",
        help="largest image a player may use (default 10, the league's limit)",
    )
    pull.add_argument(
        "--team-limit-gb", type=float, default=40.0, metavar="GB",
        help="the team's images together, each layer once (default 40, the league's limit)",
    )
    pull.add_argument("--json", action="store_true", help="print one JSON object")
    pull.set_defaults(func=_pull)


def _build(args: argparse.Namespace) -> int:
    from orchestrator import build_all, progress

    started = time.monotonic()
    with progress() as bars:
        built = build_all(base=args.base, progress=bars)
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


def _pull(args: argparse.Namespace) -> int:
    from orchestrator import progress, resolve_team_images
    from orchestrator.config import Limits, load_team
    from orchestrator.engine import connect

    loaded = load_team(args.team_config, images_required=True)
    if not args.json:
        for warning in loaded.warnings:
            print(warning)
    limits = Limits(image_gb=args.image_limit_gb, team_images_gb=args.team_limit_gb)
    with progress() as bars:
        resolved = resolve_team_images(connect(), loaded.team, limits=limits, progress=bars)
    ok = all(image.error is None for image in resolved.values())
    if args.json:
        players = {
            str(number): {
                "reference": image.reference,
                "digest": image.digest,
                "size_bytes": image.size_bytes,
                "stored_bytes": image.stored_bytes,
                "pull_attempts": image.pull_attempts,
                "error": image.error.reason if image.error else None,
            }
            for number, image in sorted(resolved.items())
        }
        print(json.dumps({"team": loaded.team.name, "ok": ok, "players": players},
                         sort_keys=True))
    else:
        for number, image in sorted(resolved.items()):
            if image.error is None:
                retried = (f", pulled at attempt {image.pull_attempts}"
                           if image.pull_attempts > 1 else "")
                print(f"player {number}: {image.digest} ({image.size_bytes / 1e6:.1f} MB"
                      f"{retried})")
            else:
                print(f"player {number}: {image.error}")
    return pull_exit_code(image.error for image in resolved.values())


def pull_exit_code(errors: Iterable[ImageError | None]) -> int:
    """0 when every player has its image (each error None); 3 (infrastructure) when every
    failure is one that trying again may cure (the registry unreachable, a 5xx, a broken
    connection); else 1."""
    from orchestrator import ImagePullError

    errors = [error for error in errors if error is not None]
    if not errors:
        return ExitCode.OK
    if all(isinstance(e, ImagePullError) and e.transient for e in errors):
        return ExitCode.INFRASTRUCTURE
    return ExitCode.FAILED
