"""Paths given by users, made absolute once, where they enter.

Every path on the command line (``--out``, game and team files, credentials, replays, schedules,
state files, log stores) goes through :func:`user_path`, the ``type=`` of its argparse argument.
From there on the program holds absolute paths only, so a relative ``--out`` reaches Docker as an
absolute bind-mount source and every message names the file it really means.
"""

from __future__ import annotations

import errno
import os
from pathlib import Path


def user_path(text: str | os.PathLike[str]) -> Path:
    """``text`` made absolute against the current directory (``~`` expanded).

    Symbolic links are kept as written (``..`` is folded away), so messages show the path the
    user would recognise.
    """
    return Path(os.path.abspath(os.path.expanduser(os.fspath(text))))


def state_dir() -> Path:
    """The runner's state on this host (``$HLVS_STATE_DIR``, default ``/var/lib/hlvs-runner``):
    the ledger of created objects, run records, capped log folders."""
    return Path(os.environ.get("HLVS_STATE_DIR", "/var/lib/hlvs-runner"))


def file_in_the_way(exc: OSError) -> Path | None:
    """The file where a folder was to be, when ``exc`` (a folder that could not be made, a path
    through a file) comes from one: ``exc``'s path or the nearest of its parents that exists,
    if that is not a folder."""
    if exc.errno not in (errno.EEXIST, errno.ENOTDIR) or not exc.filename:
        return None
    path = Path(os.fsdecode(exc.filename))
    found = next((p for p in (path, *path.parents) if p.exists()), None)
    return found if found is not None and not found.is_dir() else None


__all__ = ["file_in_the_way", "state_dir", "user_path"]
