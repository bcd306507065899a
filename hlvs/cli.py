"""The ``hlvs`` command line: parses arguments, wires objects, maps errors to exit codes.

Rules every command follows (a unit test checks them for every command that exists):

- It lives in ``hlvs/commands/<name>.py`` with ``register(subparsers)``, listed in
  :data:`COMMAND_MODULES`. At module level it imports only the standard library and
  ``orchestrator.errors`` / ``orchestrator.exitcodes`` / ``orchestrator.console``; everything
  else is imported inside the function that runs the command, so ``hlvs --help`` stays fast.
- Every sub-command and every option or argument has a ``help=`` text.
- It returns an :class:`~orchestrator.exitcodes.ExitCode` or raises an ``OrchestratorError``;
  the mapping of errors to codes is here, once. An ``OSError`` that names a file (an output
  folder that cannot be made, a full disk) is one line naming it, exit 2 (3 for the host's
  trouble: a full or read-only disk).
- Logging: WARNING by default, since most commands print their result on stdout; commands that
  run for long (a match, a schedule) ``set_defaults(log_level=logging.INFO)``. ``-v`` lowers the
  level by one step, ``-q`` raises it, before or after the command name.
- A command forwarded to another module's own parser (``hlvs bench sim``, ``hlvs render``) is
  added with :func:`forward`, and that parser names itself ``hlvs ...``.
"""

from __future__ import annotations

import argparse
import errno
import logging
import os
import sys
from collections.abc import Iterator, Sequence
from typing import Any

from hlvs.commands import (
    check,
    compose,
    images,
    logs,
    match,
    pool,
    referee,
    registry,
    schedule,
    service,
    simulator,
    viewer,
)
from orchestrator import ExitCode, OrchestratorError

PROG = "hlvs"

COMMAND_MODULES = (
    check,
    match,
    images,
    registry,
    compose,
    logs,
    schedule,
    simulator,
    viewer,
    pool,
    service,
    referee,
)

EPILOG = (
    "exit codes: 0 success, 1 the operation failed, 2 invalid input, 3 infrastructure "
    "(Docker engine, registry, network), 4 the match was decided by forfeit, 130 interrupted"
)


def _version() -> str:
    from importlib.metadata import PackageNotFoundError, version

    try:
        return version("hlvs-runner")
    except PackageNotFoundError:
        return "unknown"


class _VersionAction(argparse.Action):
    """``--version`` that reads the installed version only when asked."""

    def __init__(self, option_strings: list[str], dest: str, **kwargs: Any) -> None:
        super().__init__(option_strings, dest, nargs=0, default=argparse.SUPPRESS, **kwargs)

    def __call__(self, parser: argparse.ArgumentParser, *args: Any, **kwargs: Any) -> None:
        print(f"{PROG} {_version()}")
        parser.exit()


class Parser(argparse.ArgumentParser):
    """An argument parser whose invalid choice (a mistyped command, action or value) comes with
    "did you mean ...?" when a choice is close; its sub-command parsers are of this class too."""

    def _check_value(self, action: argparse.Action, value: Any) -> None:
        choices = action.choices
        if choices is None or value in choices:
            return
        import difflib

        names = [str(c) for c in choices]
        close = difflib.get_close_matches(str(value), names, n=1, cutoff=0.6)
        if not close:  # a prefix: "sched" for "schedule"
            close = [n for n in names if n.startswith(str(value))][:1] if value else []
        hint = f"; did you mean {close[0]!r}?" if close else ""
        raise argparse.ArgumentError(
            action, f"invalid choice: {value!r}{hint} (choose from {', '.join(names)})"
        )


def build_parser() -> argparse.ArgumentParser:
    parser = Parser(
        prog=PROG,
        description="Run RoboCup Humanoid League virtual soccer matches.",
        epilog=EPILOG,
    )
    parser.add_argument("--version", action=_VersionAction, help="print the version and exit")
    _add_verbosity(parser, default=0)
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", title="commands")
    sub.required = True
    for module in COMMAND_MODULES:
        module.register(sub)
    for child in walk(parser):
        if child is not parser and not child.get_default("forwarded"):
            _add_verbosity(child, default=argparse.SUPPRESS)
    return parser


def _add_verbosity(parser: argparse.ArgumentParser, *, default: Any) -> None:
    prefix = "" if default == 0 else "sub_"
    try:
        parser.add_argument(
            "-v", "--verbose", action="count", default=default, dest=prefix + "verbose",
            help="more log output (-vv for debug)",
        )
        parser.add_argument(
            "-q", "--quiet", action="count", default=default, dest=prefix + "quiet",
            help="less log output (errors only)",
        )
    except argparse.ArgumentError:
        pass  # the command has its own -v or -q


def walk(parser: argparse.ArgumentParser) -> Iterator[argparse.ArgumentParser]:
    """``parser`` and every sub-command parser below it, depth first."""
    yield parser
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for child in dict.fromkeys(action.choices.values()):
                yield from walk(child)


def log_level(args: argparse.Namespace) -> int:
    """The command's default level moved by one step per ``-v`` (down) or ``-q`` (up)."""
    base = int(getattr(args, "log_level", logging.WARNING))
    verbose = int(getattr(args, "verbose", 0)) + int(getattr(args, "sub_verbose", 0))
    quiet = int(getattr(args, "quiet", 0)) + int(getattr(args, "sub_quiet", 0))
    return max(logging.DEBUG, min(logging.CRITICAL, base + 10 * (quiet - verbose)))


class _StderrHandler(logging.StreamHandler):  # type: ignore[type-arg]
    """Writes to whatever ``sys.stderr`` is when a record is logged (not when configured)."""

    @property
    def stream(self) -> Any:
        return sys.stderr

    @stream.setter
    def stream(self, value: Any) -> None:
        pass


LIBRARY_LOGGERS = ("alembic", "OpenGL", "urllib3", "docker", "httpx", "httpcore", "asyncio",
                   "botocore", "boto3", "s3transfer", "paramiko", "apscheduler", "PIL",
                   "matplotlib", "sqlalchemy", "multipart", "filelock")
"""Libraries whose own lines are shown only from WARNING, whatever ``-v`` says: ``-v`` is for
this project's lines (an INFO line of Alembic or OpenGL, a DEBUG line of urllib3, is noise)."""


def configure_logging(level: int) -> None:
    for name in LIBRARY_LOGGERS:
        logging.getLogger(name).setLevel(max(level, logging.WARNING))
    fmt = (
        "%(asctime)s %(levelname)s %(name)s: %(message)s"
        if level <= logging.INFO
        else f"{PROG}: %(levelname)s: %(message)s"
    )
    handler = _StderrHandler()
    handler.setFormatter(logging.Formatter(fmt))
    logging.basicConfig(level=level, handlers=[handler], force=True)


def main(argv: Sequence[str] | None = None) -> int:
    parser = build_parser()
    args, rest = parser.parse_known_args(argv)
    if getattr(args, "forwarded", False):
        args.rest = rest  # unread, in order: the forwarded command's parser reads them
    elif rest:
        parser.error(f"unrecognized arguments: {' '.join(rest)}")
    configure_logging(log_level(args))
    try:
        return int(args.func(args))
    except KeyboardInterrupt:
        print(f"{PROG}: interrupted", file=sys.stderr)
        return ExitCode.INTERRUPTED
    except OrchestratorError as exc:
        print(f"{PROG}: {exc}", file=sys.stderr)
        return int(exc.exit_code)
    except BrokenPipeError:  # `hlvs ... | head`
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return ExitCode.OK
    except OSError as exc:
        if exc.filename is None:  # not about a file or folder: a defect, with its traceback
            raise
        return _file_error(exc)


_HOST_TROUBLE = frozenset({errno.ENOSPC, errno.EDQUOT, errno.EIO, errno.EROFS})


def _file_error(exc: OSError) -> int:
    """A file or folder the command could not read or write (an output folder where none can
    be made, a full disk): one line naming it, the traceback at debug level (``-vv``)."""
    logging.getLogger(__name__).debug("file error", exc_info=exc)
    names = str(exc.filename) + (f" -> {exc.filename2}" if exc.filename2 else "")
    reason = exc.strerror or str(exc)
    from orchestrator import file_in_the_way

    found = file_in_the_way(exc)
    if found is not None:
        names, reason = str(found), "a file where a folder is needed"
    print(f"{PROG}: {names}: {reason}", file=sys.stderr)
    return ExitCode.INFRASTRUCTURE if exc.errno in _HOST_TROUBLE else ExitCode.INVALID


if __name__ == "__main__":
    sys.exit(main())
