"""Files written private: 0600, in folders 0700 (team files, match files, logs, the database).

Files are created with their mode (``os.open``), never chmod-ed after the content is in them.
"""

from __future__ import annotations

import os
from pathlib import Path

FILE_MODE = 0o600
DIR_MODE = 0o700


def private_dir(path: Path, *, only_if_new: bool = False) -> Path:
    """``path`` and its missing parents created 0700; ``path`` itself made 0700 when it
    existed (unless ``only_if_new``: a folder the service does not own, e.g. the one that
    holds the data folder)."""
    existed = path.is_dir()
    if not existed:
        if not path.parent.is_dir():
            private_dir(path.parent, only_if_new=True)
        path.mkdir(mode=DIR_MODE, exist_ok=True)
    if not existed or not only_if_new:
        path.chmod(DIR_MODE)
    return path


def write_private(path: Path, data: bytes | str) -> Path:
    """Write ``data`` to ``path`` (replaced whole), the file 0600 from its creation."""
    raw = data.encode("utf-8") if isinstance(data, str) else data
    tmp = path.with_name(path.name + ".tmp")
    fd = os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_TRUNC, FILE_MODE)
    try:
        os.fchmod(fd, FILE_MODE)  # a leftover .tmp keeps its old mode otherwise
        with os.fdopen(fd, "wb", closefd=False) as handle:
            handle.write(raw)
    finally:
        os.close(fd)
    tmp.replace(path)
    return path


def open_private_append(path: Path) -> int:
    """A file descriptor appending to ``path`` (created 0600)."""
    return os.open(path, os.O_WRONLY | os.O_CREAT | os.O_APPEND, FILE_MODE)


def make_private_file(path: Path) -> None:
    """``path`` exists and is 0600 (an empty file created when missing, e.g. SQLite's)."""
    fd = os.open(path, os.O_WRONLY | os.O_CREAT, FILE_MODE)
    try:
        os.fchmod(fd, FILE_MODE)
    finally:
        os.close(fd)


__all__ = ["DIR_MODE", "FILE_MODE", "make_private_file", "open_private_append", "private_dir",
           "write_private"]
