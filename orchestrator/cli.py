"""The ``hlvs`` command line: parses arguments, wires objects, maps errors to exit codes.

Each sub-command lives in ``orchestrator/commands/<name>.py`` and exposes
``register(subparsers)``, which adds its parser and sets ``func(args) -> int``.
Exit codes: 0 success, 1 operation failed, 2 invalid input, 3 infrastructure, 130 interrupted.
"""

from __future__ import annotations

import argparse
import importlib
import logging
import sys
from collections.abc import Sequence

from orchestrator.errors import OrchestratorError

COMMAND_MODULES = (
    "orchestrator.commands.check",
    "orchestrator.commands.match",
    "orchestrator.commands.images",
    "orchestrator.commands.registry",
    "orchestrator.commands.compose",
    "orchestrator.commands.logs",
    "orchestrator.commands.schedule",
    "orchestrator.commands.simulator",
    "service.commands",
)


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="hlvs", description="Run RoboCup Humanoid League virtual soccer matches."
    )
    parser.add_argument("-v", "--verbose", action="count", default=0, help="more log output")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    sub.required = True
    for name in COMMAND_MODULES:
        importlib.import_module(name).register(sub)
    return parser


def configure_logging(verbosity: int) -> None:
    level = logging.WARNING if verbosity < 0 else logging.INFO if verbosity == 0 else logging.DEBUG
    logging.basicConfig(
        level=level, format="%(asctime)s %(levelname)s %(name)s: %(message)s", stream=sys.stderr
    )


def main(argv: Sequence[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    configure_logging(args.verbose)
    try:
        return int(args.func(args))
    except KeyboardInterrupt:
        print("hlvs: interrupted", file=sys.stderr)
        return 130
    except OrchestratorError as exc:
        print(f"hlvs: {exc}", file=sys.stderr)
        return exc.exit_code


if __name__ == "__main__":
    sys.exit(main())
