"""`hlvs check FILE...`: validate game.json, team_config.json, credentials.json and schedules.

Each problem is printed as one line ``file: /json/pointer: what is wrong (expected ...; did you
mean ...?)``; warnings start with ``warning:``. Exit code 0 when every file is valid (warnings
allowed), 2 when any is not.
"""

from __future__ import annotations

import argparse
import importlib
import logging
import sys
from pathlib import Path
from typing import Any, TextIO

from orchestrator.config import check_game, check_team
from orchestrator.config.detect import KINDS, Kind, kind_by_content, kind_by_name
from orchestrator.config.jsonfile import parse_json, read_text
from orchestrator.config.model import FieldClass
from orchestrator.errors import ConfigError, OrchestratorError, Problem

log = logging.getLogger(__name__)

EXIT_OK = 0
EXIT_FAILED = 1
EXIT_INVALID = 2

# Loaders written in other modules: kind -> (module, function). Skipped when not installed.
_OPTIONAL_LOADERS = {
    "credentials": ("orchestrator.config.credentials", "load_credentials"),
    "schedule": ("orchestrator.config.schedule", "load_schedule"),
}


def register(sub: Any) -> None:
    parser: argparse.ArgumentParser = sub.add_parser(
        "check",
        help="validate configuration files",
        description=(
            "Validate game.json (with the team files it references), team_config.json, "
            "credentials.json and schedule files. The kind is found from the content."
        ),
    )
    parser.add_argument("files", nargs="+", metavar="FILE", help="files to check")
    parser.add_argument("--kind", choices=KINDS, help="check every FILE as this kind")
    parser.add_argument(
        "--class",
        dest="field_class",
        choices=("KID", "ADULT"),
        help="field class for a team file checked alone (player count and pose rules)",
    )
    parser.add_argument(
        "--require-images",
        action="store_true",
        help="a player without image and dockerTag is an error (as for a match)",
    )
    parser.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    code = EXIT_OK
    for name in args.files:
        result = check_file(
            Path(name),
            kind=args.kind,
            field_class=args.field_class,
            images_required=args.require_images,
            out=sys.stdout,
        )
        code = max(code, result)
    return code


def check_file(
    path: Path,
    *,
    kind: Kind | None = None,
    field_class: FieldClass | None = None,
    images_required: bool = False,
    out: TextIO,
) -> int:
    """Check one file, print its problems to ``out``, and return its exit code."""
    try:
        found_kind, problems = _check(
            path, kind=kind, field_class=field_class, images_required=images_required
        )
    except ConfigError as exc:
        found_kind, problems = kind, exc.problems
    except OrchestratorError as exc:
        print(f"{path}: /: {exc}", file=out)
        return EXIT_INVALID
    errors = [p for p in problems if p.severity == "error"]
    for problem in errors + [p for p in problems if p.severity != "error"]:
        print(str(problem), file=out)
    if errors:
        return EXIT_INVALID
    warnings = len(problems) - len(errors)
    note = f", {warnings} warning{'s' if warnings != 1 else ''}" if warnings else ""
    print(f"{path}: ok ({found_kind}{note})", file=out)
    return EXIT_OK


def _check(
    path: Path, *, kind: Kind | None, field_class: FieldClass | None, images_required: bool
) -> tuple[Kind | None, list[Problem]]:
    text = read_text(path)  # missing, directory, empty, binary: one clean problem each
    kind = kind or kind_by_name(path)
    document: Any = None
    if kind is None or kind in ("game", "team", "credentials"):
        document = parse_json(text, file=str(path))
        kind = kind or kind_by_content(document)
    if kind is None:
        problem = Problem(
            str(path),
            "",
            "cannot tell which kind of file this is",
            expected="a game.json, team_config.json, credentials.json or schedule (or --kind)",
        )
        return None, [problem]
    if kind == "game":
        problems = check_game(path, images_required=images_required)
        for credentials in _referenced_credentials(path, document):
            problems.extend(_check_optional("credentials", credentials))
        return kind, problems
    if kind == "team":
        return kind, check_team(path, field_class=field_class, images_required=images_required)
    return kind, _check_optional(kind, path)


def _referenced_credentials(path: Path, document: Any) -> list[Path]:
    """The credentials.json files a game document names that exist (missing ones are reported
    by the game check)."""
    if not isinstance(document, dict):
        return []
    names = [document.get("public_logs")]
    names += [
        side.get("credentials")
        for side in (document.get("red"), document.get("blue"))
        if isinstance(side, dict)
    ]
    paths = [path.parent / name for name in names if isinstance(name, str) and name]
    return [p for p in dict.fromkeys(paths) if p.is_file()]


def _check_optional(kind: Kind, path: Path) -> list[Problem]:
    module_name, function = _OPTIONAL_LOADERS[kind]
    try:
        module = importlib.import_module(module_name)
    except ImportError:
        return [
            Problem(
                str(path), "", f"{kind} files cannot be checked by this version", severity="warning"
            )
        ]
    try:
        text = read_text(path)
        if kind == "credentials":
            parse_json(text, file=str(path))
        loaded = getattr(module, function)(path)
    except ConfigError as exc:
        return exc.problems
    except OrchestratorError:
        raise
    except Exception as exc:  # a loader of another module failed: report it, do not crash
        log.debug("checking %s failed", path, exc_info=True)
        return [Problem(str(path), "", f"cannot be checked: {type(exc).__name__}: {exc}")]
    warnings = getattr(loaded, "warnings", ())
    return [w for w in warnings if isinstance(w, Problem)]
