"""`hlvs check FILE...`: validate game.json, team_config.json, credentials.json and schedules.

Each problem is printed as one line ``file: /json/pointer: what is wrong (expected ...; did you
mean ...?)``; warnings start with ``warning:``. ``--json`` prints one JSON object instead and
``--format github`` prints workflow commands that GitHub shows as pull-request annotations.
Exit code 0 when every file is valid (warnings allowed), 2 when any is not.
"""

from __future__ import annotations

import argparse
import importlib
import json
import logging
import re
import sys
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import TYPE_CHECKING, Any, NotRequired, TextIO, TypedDict

from contracts import to_data
from orchestrator import ConfigError, ExitCode, OrchestratorError, Problem, user_path

if TYPE_CHECKING:
    from contracts import FieldClass, JSONObject
    from orchestrator.config import Kind
    from simulator.world.robots.team import Measurements

log = logging.getLogger(__name__)

KINDS = ("game", "team", "credentials", "schedule")
FORMATS = ("text", "json", "github")

# Loaders written in other modules: kind -> (module, function). Skipped when not installed.
_OPTIONAL_LOADERS = {
    "credentials": ("orchestrator.config.credentials", "load_credentials"),
    "schedule": ("orchestrator.config.schedule_check", "check_schedule"),
}


def register(sub: Any) -> None:
    parser: argparse.ArgumentParser = sub.add_parser(
        "check",
        help="validate configuration files",
        description=(
            "Validate game.json (with the team files it references), team_config.json, "
            "credentials.json and schedule files. The kind is found from the content."
        ),
        epilog="exit codes: 0 every file is valid (warnings allowed), 2 a file is invalid",
    )
    parser.add_argument(
        "files",
        nargs="+",
        type=user_path,
        metavar="FILE",
        help="files to check; a folder with robot_model.json is checked as a robot model package",
    )
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
    parser.add_argument(
        "--format",
        choices=FORMATS,
        default="text",
        help="text: one line per problem; json: one JSON object; github: workflow commands "
        "shown as annotations on a pull request (default: text)",
    )
    parser.add_argument("--json", action="store_true", help="same as --format json")
    parser.add_argument(
        "--official",
        action="store_true",
        help="robot model packages and team files as for an official match: free-form servos "
        "and gains (no catalogue servo), and a team file's robots of another size class than "
        "--class, are errors, not warnings (a game.json says so itself with \"official\")",
    )
    parser.set_defaults(func=run)


class FileReportRecord(TypedDict):
    """One file of ``hlvs check --json``."""

    measurements: NotRequired[JSONObject]  # Measurements.to_json() (first when there)
    devices: NotRequired[dict[str, list[str]]]  # a model's device names by kind
    file: str
    kind: str | None
    valid: bool
    problems: list[JSONObject]  # each a Problem (the root pointer written as "/")


@dataclass(slots=True)
class FileReport:
    """The outcome of checking one file."""

    file: str
    kind: str | None
    problems: list[Problem] = field(default_factory=list)
    measurements: Measurements | None = None  # robot model packages
    devices: dict[str, list[str]] = field(default_factory=dict)  # their device names by kind

    @property
    def errors(self) -> list[Problem]:
        return [p for p in self.problems if p.severity == "error"]

    @property
    def valid(self) -> bool:
        return not self.errors

    def as_json(self) -> FileReportRecord:
        record: FileReportRecord = {
            "file": self.file,
            "kind": self.kind,
            "valid": self.valid,
            "problems": [to_data(replace(p, pointer=p.pointer or "/")) for p in self.problems],
        }
        if self.measurements is None:
            return record
        return {"measurements": self.measurements.to_json(), "devices": self.devices, **record}


def run(args: argparse.Namespace) -> int:
    from contracts import FieldClass

    reports = [
        check_report(
            name,
            kind=args.kind,
            field_class=FieldClass(args.field_class.lower()) if args.field_class else None,
            images_required=args.require_images,
            official=args.official,
        )
        for name in args.files
    ]
    fmt = "json" if args.json else args.format
    if fmt == "json":
        valid = all(r.valid for r in reports)
        print(json.dumps({"valid": valid, "files": [r.as_json() for r in reports]}, indent=2))
    elif fmt == "github":
        for report in reports:
            print_github(report, out=sys.stdout)
    else:
        for report in reports:
            print_text(report, out=sys.stdout)
    return ExitCode.OK if all(r.valid for r in reports) else ExitCode.INVALID


def check_file(
    path: Path,
    *,
    kind: Kind | None = None,
    field_class: FieldClass | None = None,
    images_required: bool = False,
    out: TextIO,
) -> int:
    """Check one file, print its problems to ``out``, and return its exit code."""
    report = check_report(
        path, kind=kind, field_class=field_class, images_required=images_required
    )
    print_text(report, out=out)
    return ExitCode.OK if report.valid else ExitCode.INVALID


def check_report(
    path: Path,
    *,
    kind: Kind | None = None,
    field_class: FieldClass | None = None,
    images_required: bool = False,
    official: bool = False,
) -> FileReport:
    """Check one file (or robot model package) and return every problem found (nothing
    printed); ``official``: model packages and team files as for an official match."""
    from orchestrator.config import check_model, is_model_package, model_devices

    if is_model_package(path):
        problems, measurements = check_model(path, official=official)
        devices = model_devices(path) if measurements is not None else {}
        return FileReport(str(path), "robot model", problems, measurements, devices)
    try:
        found_kind, problems = _check(
            path, kind=kind, field_class=field_class, images_required=images_required,
            official=official,
        )
    except ConfigError as exc:
        found_kind, problems = kind, exc.problems
    except OrchestratorError as exc:
        found_kind, problems = kind, [Problem(str(path), "", str(exc))]
    return FileReport(file=str(path), kind=found_kind, problems=list(problems))


def print_text(report: FileReport, *, out: TextIO) -> None:
    if report.measurements is not None:
        from orchestrator.config import describe

        print(f"{report.file}: {describe(report.measurements)}", file=out)
        for kind, names in report.devices.items():
            listed = ", ".join(json.dumps(name, ensure_ascii=False) for name in names)
            print(f"  {_KIND_LABELS.get(kind, kind)} ({len(names)}): {listed}", file=out)
    for problem in report.errors + [p for p in report.problems if p.severity != "error"]:
        print(str(problem), file=out)
    if report.valid:
        warnings = len([p for p in report.problems if p.severity == "warning"])
        notes = len(report.problems) - warnings
        note = f", {warnings} warning{'s' if warnings != 1 else ''}" if warnings else ""
        note += f", {notes} note{'s' if notes != 1 else ''}" if notes else ""
        print(f"{report.file}: ok ({report.kind}{note})", file=out)


_KIND_LABELS = {
    "motor": "motors",
    "position_sensor": "position sensors",
    "accelerometer": "accelerometers",
    "gyro": "gyros",
    "camera": "camera",
    "force": "force sensors",
}


def print_github(report: FileReport, *, out: TextIO) -> None:
    """GitHub Actions workflow commands (``::error file=...,line=...,title=...::message``)."""
    for problem in report.problems:
        level = {"error": "error", "note": "notice"}.get(problem.severity, "warning")
        title = f"{problem.pointer or '/'}"
        text = str(problem).removeprefix("warning: ")
        line = line_of(Path(problem.file), problem.pointer)
        where = f",line={line}" if line else ""
        print(
            f"::{level} file={_gh_property(problem.file)}{where},title={_gh_property(title)}"
            f"::{_gh_data(text)}",
            file=out,
        )
    if report.valid:
        print(f"{report.file}: ok ({report.kind})", file=out)


def line_of(path: Path, pointer: str) -> int | None:
    """The line of a JSON file where the member a JSON pointer names starts (found by looking
    for each key in turn after the previous one), or None when it cannot be told."""
    try:
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError):
        return None
    position = 0
    for token in [t for t in pointer.split("/") if t]:
        key = token.replace("~1", "/").replace("~0", "~")
        found = re.compile(r'"' + re.escape(json.dumps(key)[1:-1]) + r'"\s*:').search(
            text, position
        )
        if found is None:
            return None if position == 0 else text.count("\n", 0, position) + 1
        position = found.start()
    return text.count("\n", 0, position) + 1


def _gh_data(text: str) -> str:
    return text.replace("%", "%25").replace("\r", "%0D").replace("\n", "%0A")


def _gh_property(text: str) -> str:
    return _gh_data(text).replace(":", "%3A").replace(",", "%2C")


def _check(
    path: Path,
    *,
    kind: Kind | None,
    field_class: FieldClass | None,
    images_required: bool,
    official: bool = False,
) -> tuple[Kind | None, list[Problem]]:
    from orchestrator.config import (
        check_game,
        check_team,
        kind_by_content,
        kind_by_name,
        parse_json,
        read_text,
    )

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
        return kind, check_team(path, field_class=field_class, images_required=images_required,
                                official=official)
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
    from orchestrator.config import parse_json, read_text

    module_name, function = _OPTIONAL_LOADERS[kind]
    try:
        module = importlib.import_module(module_name)
    except ImportError:
        return [
            Problem(
                str(path), "", f"{kind} files cannot be checked by this version", severity="warning"
            )
        ]
    loader_log = logging.getLogger(module_name)
    level = loader_log.level
    loader_log.setLevel(logging.ERROR)  # its warnings are returned and printed as the result
    try:
        text = read_text(path)
        if kind == "credentials":
            parse_json(text, file=str(path))
        if kind == "schedule":  # a match whose stream has started is refused
            from datetime import UTC, datetime

            loaded = getattr(module, function)(path, now=datetime.now(UTC))
        else:
            loaded = getattr(module, function)(path)
        if isinstance(loaded, list):  # a checker: every problem, errors included
            return [p for p in loaded if isinstance(p, Problem)]
    except ConfigError as exc:
        return exc.problems
    except OrchestratorError:
        raise
    except Exception as exc:  # a loader of another module failed: report it, do not crash
        log.debug("checking %s failed", path, exc_info=True)
        return [Problem(str(path), "", f"cannot be checked: {type(exc).__name__}: {exc}")]
    finally:
        loader_log.setLevel(level)
    warnings = getattr(loaded, "warnings", ())
    return [w for w in warnings if isinstance(w, Problem)]
