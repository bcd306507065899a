"""Commands forwarded unread to another module's parser (``hlvs bench sim``, ``hlvs render``)."""

from __future__ import annotations

import argparse
from typing import Any


def forward(
    sub: Any, name: str, *, help: str, func: Any, **kwargs: Any
) -> argparse.ArgumentParser:
    """A sub-command whose arguments (``--help`` included) go to another parser unread.

    ``func(args)`` gets ``args.rest``, the arguments after the command name.
    """
    parser: argparse.ArgumentParser = sub.add_parser(
        name, help=help, add_help=False, usage=f"{sub._prog_prefix} {name} ...", **kwargs
    )
    parser.set_defaults(func=func, forwarded=True)
    return parser


__all__ = ["forward"]
