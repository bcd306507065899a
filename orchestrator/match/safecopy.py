"""Copy a folder a team wrote, taking only regular files and directories.

A robot controls everything in its ``/robocup-logs``: symbolic links (to ``/etc/shadow``, ``/``,
``/proc/1/environ``), named pipes that block a reader forever, sockets, device nodes. Nothing of
that is followed, opened or copied: such entries are listed as skipped with their kind. Files are
opened with ``O_NOFOLLOW | O_NONBLOCK`` and checked again with ``fstat`` after opening, so an entry
swapped for a link or a pipe between the listing and the copy is skipped too. A file that cannot
be read is skipped with the reason; nothing here raises because of what the folder holds.
"""

from __future__ import annotations

import logging
import os
import stat
from dataclasses import dataclass, field
from pathlib import Path

from contracts.match_results import LogFolderCopy

log = logging.getLogger(__name__)

MAX_LISTED = 100  # skipped entries named in the result; the rest are only counted
CHUNK = 1 << 20


@dataclass(slots=True)
class CopyReport:
    files: int = 0
    bytes: int = 0
    skipped: list[dict[str, str]] = field(default_factory=list)  # {"path", "kind"}
    skipped_count: int = 0

    def skip(self, path: str, kind: str) -> None:
        self.skipped_count += 1
        if len(self.skipped) < MAX_LISTED:
            self.skipped.append({"path": path, "kind": kind})

    def record(self) -> LogFolderCopy:
        """What ``results.json`` keeps of the copy."""
        return LogFolderCopy(files=self.files, bytes=self.bytes, skipped=tuple(self.skipped),
                             skipped_count=self.skipped_count)


def kind_of(mode: int) -> str:
    if stat.S_ISLNK(mode):
        return "symlink"
    if stat.S_ISFIFO(mode):
        return "pipe"
    if stat.S_ISSOCK(mode):
        return "socket"
    if stat.S_ISCHR(mode):
        return "character device"
    if stat.S_ISBLK(mode):
        return "block device"
    if stat.S_ISDIR(mode):
        return "directory"
    if stat.S_ISREG(mode):
        return "file"
    return "unknown"


def copy_tree(source: Path, destination: Path, *, file_mode: int = 0o600,
              dir_mode: int = 0o700) -> CopyReport:
    """Copy the regular files and directories under ``source`` into ``destination``."""
    report = CopyReport()
    destination.mkdir(parents=True, exist_ok=True)
    os.chmod(destination, dir_mode)
    _copy_dir(source, destination, "", report, file_mode, dir_mode)
    return report


def _copy_dir(source: Path, destination: Path, relative: str, report: CopyReport,
              file_mode: int, dir_mode: int) -> None:
    try:
        entries = sorted(os.scandir(source), key=lambda e: e.name)
    except OSError as exc:
        report.skip(relative or ".", f"unreadable directory ({exc.strerror})")
        return
    for entry in entries:
        rel = f"{relative}/{entry.name}" if relative else entry.name
        try:
            mode = entry.stat(follow_symlinks=False).st_mode
        except OSError as exc:
            report.skip(rel, f"unreadable ({exc.strerror})")
            continue
        target = destination / entry.name
        if stat.S_ISDIR(mode):
            try:
                target.mkdir(exist_ok=True)
                os.chmod(target, dir_mode, follow_symlinks=False)
            except OSError as exc:
                report.skip(rel, f"directory not created ({exc.strerror})")
                continue
            _copy_dir(Path(entry.path), target, rel, report, file_mode, dir_mode)
        elif stat.S_ISREG(mode):
            _copy_file(Path(entry.path), target, rel, report, file_mode)
        else:
            report.skip(rel, kind_of(mode))


def _copy_file(source: Path, target: Path, rel: str, report: CopyReport, file_mode: int) -> None:
    try:
        fd = os.open(source, os.O_RDONLY | os.O_NOFOLLOW | os.O_NONBLOCK)
    except OSError as exc:
        report.skip(rel, f"unreadable ({exc.strerror})")
        return
    try:
        mode = os.fstat(fd).st_mode
        if not stat.S_ISREG(mode):
            report.skip(rel, kind_of(mode))
            return
        out = os.open(target, os.O_WRONLY | os.O_CREAT | os.O_TRUNC | os.O_NOFOLLOW, file_mode)
        copied = 0
        try:
            os.fchmod(out, file_mode)
            while chunk := os.read(fd, CHUNK):
                os.write(out, chunk)
                copied += len(chunk)
        finally:
            os.close(out)
        report.files += 1
        report.bytes += copied
    except OSError as exc:
        report.skip(rel, f"not copied ({exc.strerror})")
    finally:
        os.close(fd)


def restrict(folder: Path) -> None:
    """Make ``folder`` readable by its owner only: directories 0700, regular files 0600
    (links are neither followed nor changed)."""
    if not folder.is_dir() or folder.is_symlink():
        return
    os.chmod(folder, 0o700)
    for root, dirs, files in os.walk(folder, followlinks=False):
        for name in dirs + files:
            path = os.path.join(root, name)
            try:
                mode = os.lstat(path).st_mode
                if stat.S_ISDIR(mode):
                    os.chmod(path, 0o700)
                elif stat.S_ISREG(mode):
                    os.chmod(path, 0o600)
            except OSError as exc:
                log.warning("could not restrict %s: %s", path, exc)


def sweep(folder: Path) -> CopyReport:
    """In place: remove every entry under ``folder`` that is not a regular file or directory
    (the robot wrote straight into the output folder); returns what stays and what went."""
    report = CopyReport()
    for root, dirs, files in os.walk(folder, topdown=True, followlinks=False):
        for name in sorted(dirs + files):
            path = Path(root) / name
            rel = str(path.relative_to(folder))
            try:
                mode = path.lstat().st_mode
            except OSError:
                continue
            if stat.S_ISDIR(mode):
                os.chmod(path, 0o700)
            elif stat.S_ISREG(mode):
                os.chmod(path, 0o600)
                report.files += 1
                report.bytes += path.lstat().st_size
            else:
                report.skip(rel, kind_of(mode))
                try:
                    path.unlink()
                except OSError as exc:
                    log.warning("could not remove %s from %s: %s", rel, folder, exc)
        dirs[:] = [d for d in dirs if (Path(root) / d).is_dir() and
                   not (Path(root) / d).is_symlink()]
    return report


__all__ = ["CopyReport", "MAX_LISTED", "copy_tree", "kind_of", "restrict", "sweep"]
