"""``hlvs registry enforce``: keep a league registry within the image and team size limits.

Deletes images over ``--image-limit-gb``, then random images (seeded) of each team over
``--team-limit-gb`` until the team is under; prints what was deleted (``--json``: one JSON object).
"""

from __future__ import annotations

import argparse
import json
import os
import random
from typing import Any

from orchestrator import ConfigError, Problem

GB = 1_000_000_000


def register(sub: Any) -> None:
    parser: argparse.ArgumentParser = sub.add_parser(
        "registry", help="league registry maintenance (size limits)"
    )
    actions = parser.add_subparsers(dest="registry_action", metavar="ACTION")
    actions.required = True
    enforce = actions.add_parser(
        "enforce", help="delete images over the image limit, then random ones over the team limit"
    )
    enforce.add_argument("--url", required=True, help="registry base URL, e.g. http://127.0.0.1:5000")
    enforce.add_argument("--user", help="registry user (HTTP basic authentication)")
    enforce.add_argument(
        "--password", help="registry password (default: $HLVS_REGISTRY_PASSWORD)"
    )
    enforce.add_argument(
        "--image-limit-gb", type=float, default=10.0, metavar="GB",
        help="largest image (default 10, the league's limit)",
    )
    enforce.add_argument(
        "--team-limit-gb", type=float, default=40.0, metavar="GB",
        help="a team's images together (default 40, the league's limit)",
    )
    enforce.add_argument(
        "--team-of",
        action="append",
        default=[],
        metavar="PREFIX=TEAM",
        help="repositories starting with PREFIX belong to TEAM (repeatable); "
        "default: the first path component of the repository",
    )
    enforce.add_argument("--seed", type=int, help="seed of the random deletions (default: random)")
    enforce.add_argument("--dry-run", action="store_true", help="report, delete nothing")
    enforce.add_argument("--json", action="store_true", help="print one JSON object")
    enforce.set_defaults(func=_enforce)


def _enforce(args: argparse.Namespace) -> int:
    from orchestrator.registry import RegistryClient, TeamRule, enforce

    problems = []
    for name in ("image_limit_gb", "team_limit_gb"):
        if getattr(args, name) < 0:
            flag = "--" + name.replace("_", "-")
            problems.append(Problem("(command line)", flag, "negative limit", "a size >= 0"))
    if not args.url.startswith(("http://", "https://")):
        problems.append(
            Problem("(command line)", "--url", f"{args.url!r} is not a URL", "http(s)://HOST:PORT")
        )
    try:
        team_of = TeamRule.parse(args.team_of)
    except ValueError as exc:
        problems.append(Problem("(command line)", "--team-of", str(exc)))
    if problems:
        raise ConfigError(problems)
    password = args.password or os.environ.get("HLVS_REGISTRY_PASSWORD")
    seed = args.seed if args.seed is not None else random.SystemRandom().randrange(2**31)
    report = enforce(
        RegistryClient(args.url, username=args.user, password=password),
        image_limit_bytes=round(args.image_limit_gb * GB),
        team_limit_bytes=round(args.team_limit_gb * GB),
        seed=seed,
        team_of=team_of,
        dry_run=args.dry_run,
    )
    if args.json:
        print(json.dumps(report, sort_keys=True))
        return 0
    verb = "would delete" if args.dry_run else "deleted"
    for entry in report["deleted"]:
        tags = ",".join(entry["tags"])
        print(
            f"{verb} {entry['repository']}:{tags} ({entry['size_bytes'] / 1e6:.1f} MB, "
            f"team {entry['team']}, {entry['reason']})"
        )
    for team, totals in report["teams"].items():
        print(
            f"team {team}: {totals['images']} images, "
            f"{totals['before_bytes'] / 1e9:.3f} GB -> {totals['after_bytes'] / 1e9:.3f} GB"
        )
    print(f"seed {seed}; {len(report['deleted'])} images {verb}")
    if report["deleted"] and not args.dry_run:
        print("space returns after the registry's garbage collector runs")
    return 0
