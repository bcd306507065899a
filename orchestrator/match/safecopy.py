"""Copy a folder a team wrote, taking only regular files and directories.

A robot controls everything in its ``/robocup-logs``: symbolic links (to ``/etc/shadow``, ``/``,
``/proc/1/environ``), named pipes that block a reader forever, sockets, device nodes. Nothing of
that is followed, opened or copied: such entries are listed as skipped with their kind. Files are
opened with ``O_NOFOLLOW | O_NONBLOCK`` and checked again with ``fstat`` after opening, so an entry
swapped for a link or a pipe between the listing and the copy is skipped too. A file that cannot
be read is skipped with the reason; nothing here raises because of what the folder holds.
"""

from __future__ import annotations

import contextlib
import errno
import itertools
import logging
import os
import stat
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path

from contracts import LogFolderCopy

log = logging.getLogger(__name__)

MAX_LISTED = 100  # skipped entries named in the result; the rest are only counted
MAX_DEPTH = 100  # folders nested deeper are not collected
CHUNK = 1 << 20


@dataclass(slots=True)
class CopyReport:
    files: int = 0
    bytes: int = 0
    skipped: list[dict[str, str]] = field(default_factory=list)  # {"path", "kind"}
    skipped_count: int = 0
    links: int = 0  # files that were further names of a file already counted
    stopped: str | None = None  # why the copy stopped before the end (the size limit)

    def skip(self, path: str, kind: str) -> None:
        self.skipped_count += 1
        if len(self.skipped) < MAX_LISTED:
            self.skipped.append({"path": path, "kind": kind})

    def record(self) -> LogFolderCopy:
        """What ``results.json`` keeps of the copy."""
        return LogFolderCopy(files=self.files, bytes=self.bytes, skipped=tuple(self.skipped),
                             skipped_count=self.skipped_count, stopped=self.stopped)


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
              dir_mode: int = 0o700, limit_bytes: int | None = None,
              max_depth: int = MAX_DEPTH) -> CopyReport:
    """Copy the regular files and directories under ``source`` into ``destination``.

    The walk is iterative (no recursion however deep the folder nests) and goes at most
    ``max_depth`` folders down. Holes of sparse files stay holes and a file with several hard
    links is copied once (the other names become links to that copy), so the copy takes no more
    space on the host than the folder took in its capped file system; ``report.bytes`` counts the
    data written. Once ``limit_bytes`` are written the copy stops, with the reason in
    ``report.stopped``.
    """
    report = CopyReport()
    destination.mkdir(parents=True, exist_ok=True)
    os.chmod(destination, dir_mode)
    budget = _Budget(limit_bytes)
    links: dict[tuple[int, int], Path] = {}
    pending: list[tuple[Path, Path, str, int]] = [(source, destination, "", 0)]
    while pending and report.stopped is None:
        directory, target_dir, relative, depth = pending.pop()
        try:
            entries = sorted(os.scandir(directory), key=lambda e: e.name)
        except OSError as exc:
            report.skip(relative or ".", f"unreadable directory ({exc.strerror})")
            continue
        below: list[tuple[Path, Path, str, int]] = []
        for entry in entries:
            if report.stopped is not None:
                break
            rel = f"{relative}/{entry.name}" if relative else entry.name
            try:
                info = entry.stat(follow_symlinks=False)
            except OSError as exc:
                report.skip(rel, f"unreadable ({exc.strerror})")
                continue
            target = target_dir / entry.name
            if stat.S_ISDIR(info.st_mode):
                if depth + 1 > max_depth:
                    report.skip(rel, f"directory nested deeper than {max_depth} folders")
                    continue
                try:
                    target.mkdir(exist_ok=True)
                    os.chmod(target, dir_mode, follow_symlinks=False)
                except OSError as exc:
                    report.skip(rel, f"directory not created ({exc.strerror})")
                    continue
                below.append((Path(entry.path), target, rel, depth + 1))
            elif stat.S_ISREG(info.st_mode):
                key = (info.st_dev, info.st_ino)
                first = links.get(key) if info.st_nlink > 1 else None
                if first is not None:
                    _link(first, target, rel, report)
                    continue
                if _copy_file(Path(entry.path), target, rel, report, file_mode, budget) and \
                        info.st_nlink > 1:
                    links[key] = target
            else:
                report.skip(rel, kind_of(info.st_mode))
        pending.extend(reversed(below))  # depth first, in name order
    return report


class _Budget:
    """What may still be written; None: no limit."""

    def __init__(self, limit_bytes: int | None) -> None:
        self.limit = limit_bytes
        self.used = 0

    def allow(self, wanted: int) -> int:
        if self.limit is None:
            return wanted
        return max(0, min(wanted, self.limit - self.used))


def _link(first: Path, target: Path, rel: str, report: CopyReport) -> None:
    """Another name of a file already copied: a hard link to the copy (no more bytes)."""
    try:
        os.link(first, target, follow_symlinks=False)
        report.files += 1
        report.links += 1
    except OSError as exc:
        report.skip(rel, f"hard link not made ({exc.strerror})")


def _segments(fd: int, size: int) -> Iterator[tuple[int, int]]:
    """(offset, length) of the data in ``fd``; the holes of a sparse file are left out."""
    offset = 0
    while offset < size:
        try:
            start = os.lseek(fd, offset, os.SEEK_DATA)
        except OSError as exc:
            if exc.errno == errno.ENXIO:  # only a hole is left
                return
            yield offset, size - offset  # no SEEK_DATA on this file system: all of it
            return
        try:
            end = os.lseek(fd, start, os.SEEK_HOLE)
        except OSError:
            end = size
        end = min(end, size)
        if end <= start:
            return
        yield start, end - start
        offset = end


def _copy_file(source: Path, target: Path, rel: str, report: CopyReport, file_mode: int,
               budget: _Budget) -> bool:
    """Copy one file (its data segments only); True when it was copied, whole or cut at the
    limit."""
    try:
        fd = os.open(source, os.O_RDONLY | os.O_NOFOLLOW | os.O_NONBLOCK)
    except OSError as exc:
        report.skip(rel, f"unreadable ({exc.strerror})")
        return False
    try:
        info = os.fstat(fd)
        if not stat.S_ISREG(info.st_mode):
            report.skip(rel, kind_of(info.st_mode))
            return False
        out = os.open(target, os.O_WRONLY | os.O_CREAT | os.O_TRUNC | os.O_NOFOLLOW, file_mode)
        copied = 0
        end = info.st_size
        try:
            os.fchmod(out, file_mode)
            for start, length in _segments(fd, info.st_size):
                offset, left = start, length
                while left > 0:
                    allowed = budget.allow(min(CHUNK, left))
                    if allowed == 0:
                        end = offset
                        report.stopped = (
                            f"stopped at the limit of {budget.limit} bytes in {rel} (offset "
                            f"{offset}); later files were not collected")
                        break
                    chunk = os.pread(fd, allowed, offset)
                    if not chunk:
                        left = 0
                        break
                    os.pwrite(out, chunk, offset)
                    offset += len(chunk)
                    left -= len(chunk)
                    copied += len(chunk)
                    budget.used += len(chunk)
                if report.stopped is not None:
                    break
            os.ftruncate(out, end)  # the trailing hole, or the cut at the limit
        finally:
            os.close(out)
        report.files += 1
        report.bytes += copied
        return True
    except OSError as exc:
        report.skip(rel, f"not copied ({exc.strerror})")
        return False
    finally:
        os.close(fd)


def _walk(folder: Path, max_depth: int | None = None
          ) -> Iterator[tuple[Path, os.stat_result, int]]:
    """Every entry under ``folder`` (not following links), iteratively: (path, lstat, depth).
    A directory deeper than ``max_depth`` is yielded but not entered."""
    pending: list[tuple[Path, int]] = [(folder, 0)]
    while pending:
        directory, depth = pending.pop()
        try:
            names = sorted(os.listdir(directory))
        except OSError as exc:
            log.warning("cannot list %s: %s", directory, exc)
            continue
        for name in names:
            path = directory / name
            try:
                info = os.lstat(path)
            except OSError:
                continue
            yield path, info, depth + 1
            if stat.S_ISDIR(info.st_mode) and (max_depth is None or depth + 1 <= max_depth):
                pending.append((path, depth + 1))


def restrict(folder: Path) -> None:
    """Make ``folder`` readable by its owner only: directories 0700, regular files 0600
    (links are neither followed nor changed)."""
    if not folder.is_dir() or folder.is_symlink():
        return
    os.chmod(folder, 0o700)
    for path, info, _ in _walk(folder):
        try:
            if stat.S_ISDIR(info.st_mode):
                os.chmod(path, 0o700)
            elif stat.S_ISREG(info.st_mode):
                os.chmod(path, 0o600)
        except OSError as exc:
            log.warning("could not restrict %s: %s", path, exc)


def remove_tree(folder: Path) -> None:
    """Delete ``folder`` and everything under it, however deep, in time linear in the number of
    entries: each directory is first moved up into ``folder`` (by its file descriptors), so no
    path grows with the depth and nothing recurses; links are never followed."""
    if folder.is_symlink() or not folder.is_dir():
        folder.unlink(missing_ok=True)
        return
    flags = os.O_RDONLY | os.O_DIRECTORY | os.O_NOFOLLOW
    try:
        top = os.open(folder, flags)
    except OSError as exc:
        log.warning("cannot remove %s: %s", folder, exc)
        return
    moved = itertools.count()
    try:
        pending: list[str | None] = [None]  # None: the top folder itself, else a name in it
        while pending:
            name = pending.pop()
            try:
                fd = top if name is None else os.open(name, flags, dir_fd=top)
            except OSError:
                continue
            try:
                for entry in list(os.scandir(fd)):
                    with contextlib.suppress(OSError):
                        if entry.is_dir(follow_symlinks=False):
                            if name is None:
                                pending.append(entry.name)
                                continue
                            staged = f".hlvs-removing-{next(moved)}"
                            os.rename(entry.name, staged, src_dir_fd=fd, dst_dir_fd=top)
                            pending.append(staged)
                        else:
                            os.unlink(entry.name, dir_fd=fd)
            finally:
                if fd != top:
                    os.close(fd)
            if name is not None:
                with contextlib.suppress(OSError):
                    os.rmdir(name, dir_fd=top)
    finally:
        os.close(top)
    with contextlib.suppress(OSError):
        folder.rmdir()


def sweep(folder: Path, *, max_depth: int = MAX_DEPTH) -> CopyReport:
    """In place: remove every entry under ``folder`` that is not a regular file or directory,
    and every directory nested deeper than ``max_depth`` (the robot wrote straight into the
    output folder); returns what stays (allocated bytes, hard links once) and what went."""
    report = CopyReport()
    seen: set[tuple[int, int]] = set()
    for path, info, depth in _walk(folder, max_depth):
        rel = str(path.relative_to(folder))
        mode = info.st_mode
        if stat.S_ISDIR(mode):
            if depth > max_depth:
                report.skip(rel, f"directory nested deeper than {max_depth} folders")
                remove_tree(path)
                continue
            with contextlib.suppress(OSError):
                os.chmod(path, 0o700)
        elif stat.S_ISREG(mode):
            with contextlib.suppress(OSError):
                os.chmod(path, 0o600)
            report.files += 1
            if (info.st_dev, info.st_ino) in seen:
                report.links += 1
                continue
            seen.add((info.st_dev, info.st_ino))
            report.bytes += min(info.st_size, info.st_blocks * 512)
        else:
            report.skip(rel, kind_of(mode))
            try:
                path.unlink()
            except OSError as exc:
                log.warning("could not remove %s from %s: %s", rel, folder, exc)
    return report


__all__ = [
    "CopyReport", "MAX_DEPTH", "MAX_LISTED", "copy_tree", "kind_of", "remove_tree", "restrict",
    "sweep",
]
