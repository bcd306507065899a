"""Size-capped ``/robocup-logs`` folders: one loop-mounted ext4 file system per robot.

A robot that writes more than its cap gets ENOSPC in its own folder and fills nothing else. The
image files are sparse (a 10 GB cap costs nothing until written). They live under
``$HLVS_STATE_DIR`` (default ``/var/lib/hlvs-runner``) in ``logfs/<match_id>/``, so that
:func:`cleanup` finds the mounts of a match after a crash. Needs root (mkfs, mount); without root
a plain folder without a cap is used and the result says so.
"""

from __future__ import annotations

import contextlib
import hashlib
import logging
import os
import re
import shutil
import subprocess
from dataclasses import dataclass
from pathlib import Path

from orchestrator.errors import InfrastructureError
from orchestrator.match.safecopy import CopyReport, copy_tree, remove_tree, sweep
from orchestrator.paths import state_dir

log = logging.getLogger(__name__)


_PLAIN = re.compile(r"[A-Za-z0-9][A-Za-z0-9_.-]{0,99}")


def safe_name(text: str) -> str:
    """``text`` usable as a Docker object name part and as one path component, unique by
    construction: a valid match id (letters, digits, '_', '.', '-', starting with a letter or
    digit) is itself; any other text becomes ``_<cleaned>-<SHA-256>``, which no valid id can
    be (it starts with '_'), so "Bit Bots" and "Bit-Bots" never share a folder or a name."""
    if _PLAIN.fullmatch(text):
        return text
    cleaned = re.sub(r"[^A-Za-z0-9_.-]", "-", text)[:40]
    digest = hashlib.sha256(text.encode("utf-8", "surrogatepass")).hexdigest()[:32]
    return f"_{cleaned}-{digest}"


@dataclass(frozen=True, slots=True, kw_only=True)
class LogFolder:
    path: Path  # the folder bind-mounted at /robocup-logs
    cap_bytes: int | None  # None: no cap could be applied
    image: Path | None = None  # the ext4 image file when capped


def _run(*args: str) -> None:
    result = subprocess.run(list(args), capture_output=True, text=True, check=False, timeout=60)
    if result.returncode != 0:
        raise InfrastructureError(
            f"{' '.join(args)} failed ({result.returncode}): {result.stderr.strip()}"
        )


def can_cap() -> bool:
    return os.geteuid() == 0 and shutil.which("mkfs.ext4") is not None


def create(*, match_id: str, name: str, cap_bytes: int, fallback_dir: Path) -> LogFolder:
    """A folder for one robot's logs, capped at ``cap_bytes`` when possible."""
    if not can_cap():
        fallback_dir.mkdir(parents=True, exist_ok=True)
        fallback_dir.chmod(0o777)
        log.warning("no root: %s has no size cap", fallback_dir)
        return LogFolder(path=fallback_dir, cap_bytes=None)
    base = state_dir() / "logfs" / safe_name(match_id)
    base.mkdir(parents=True, exist_ok=True)
    image = base / f"{name}.img"
    mountpoint = base / name
    mountpoint.mkdir(exist_ok=True)
    with image.open("wb") as handle:
        handle.truncate(cap_bytes)
    _run("mkfs.ext4", "-q", "-F", "-m", "0", "-E", "lazy_itable_init=1,root_owner=0:0", str(image))
    _run("mount", "-o", "loop,nosuid,nodev,noexec", str(image), str(mountpoint))
    mountpoint.chmod(0o777)
    lost = mountpoint / "lost+found"
    if lost.is_dir():
        shutil.rmtree(lost, ignore_errors=True)
    log.info("log folder %s mounted (%d MB cap)", mountpoint, cap_bytes // 1_000_000)
    return LogFolder(path=mountpoint, cap_bytes=cap_bytes, image=image)


def collect(folder: LogFolder, destination: Path, *, limit_bytes: int | None = None
            ) -> CopyReport:
    """Copy the folder's regular files and directories to ``destination`` (see
    :mod:`orchestrator.match.safecopy`), at most ``limit_bytes`` (default: the folder's cap),
    and release the folder, whatever the team left in it. Only a failure to release the mount
    raises: whatever breaks the copy costs this folder's logs, nothing else."""
    limit = limit_bytes if limit_bytes is not None else folder.cap_bytes
    try:
        destination.mkdir(parents=True, exist_ok=True)
        if folder.path.resolve() != destination.resolve():
            report = copy_tree(folder.path, destination, limit_bytes=limit)
        else:
            report = sweep(destination)
    except Exception as exc:  # noqa: BLE001 - a team's folder never breaks the match record
        report = CopyReport()
        report.skip(".", f"not collected ({type(exc).__name__}: {exc})")
        report.stopped = f"collection failed: {type(exc).__name__}: {exc}"
        log.warning("log folder %s not collected: %s", folder.path, exc)
    finally:
        if folder.image is not None:
            release(folder)
    return report


def release(folder: LogFolder) -> None:
    """Unmount (lazily when a plain unmount fails) and delete the folder and its image."""
    if folder.image is None:
        return
    if _is_mounted(folder.path):
        try:
            _run("umount", str(folder.path))
        except InfrastructureError as exc:
            log.warning("%s; unmounting lazily", exc)
            _run("umount", "-l", str(folder.path))
    folder.image.unlink(missing_ok=True)
    remove_tree(folder.path)
    with contextlib.suppress(OSError):  # the match's folder, once its last robot is released
        folder.path.parent.rmdir()


def _mounts() -> list[str]:
    try:
        lines = Path("/proc/mounts").read_text().splitlines()
    except OSError:
        return []
    return [line.split()[1].replace("\\040", " ") for line in lines if len(line.split()) > 1]


def _is_mounted(path: Path) -> bool:
    return str(path) in _mounts()


def mounted(*, match_id: str | None = None) -> list[str]:
    """The capped folders still mounted (of one match, or all), as :func:`cleanup` finds them."""
    root = state_dir() / "logfs"
    if match_id is not None:
        root = root / safe_name(match_id)
    return sorted(p for p in _mounts() if p.startswith(str(root) + "/"))


def cleanup(*, match_id: str | None = None) -> int:
    """Unmount and delete what crashed runs left (of one match, or all); returns the count."""
    root = state_dir() / "logfs"
    if match_id is not None:
        root = root / safe_name(match_id)
    count = 0
    for mountpoint in mounted(match_id=match_id):
        _run("umount", "-l", mountpoint)
        count += 1
    if root.is_dir():
        shutil.rmtree(root, ignore_errors=True)
    return count


__all__ = [
    "LogFolder", "can_cap", "cleanup", "collect", "create", "mounted", "release", "safe_name",
    "state_dir",
]
