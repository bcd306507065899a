"""The robots' start gate: nothing of a robot runs before its bandwidth limits are in place.

A robot's traffic is shaped inside its network namespace, which the engine makes when the
container starts. Without the gate each robot needs a second container, a *holder* that owns
the namespace and is shaped before the robot container joins it (:mod:`orchestrator.match.layout`):
17 container starts for 8 robots and the simulator. With it the robot container is the only
one: it starts with a small static program (``native/start_gate.c``) as its entry point, bound
read-only into it, that waits for a file the orchestrator writes once the namespace is shaped
(:func:`release`) and then replaces itself with the image's entry point and command, as the
engine would have run them. On our 2-CPU machine eight robots with their holders took 1.27-1.45
s to start and shape, eight behind the gate 1.07-1.17 s (1.81-1.99 against 1.47-1.60 s under
gVisor's runsc).

The gate is built once per source version with the machine's C compiler (``$CC``, else ``cc``
or ``gcc``), statically, into the user's cache; without a compiler or a static C library the
robots start behind holders as before (said once in the log).
"""

from __future__ import annotations

import functools
import hashlib
import logging
import os
import shutil
import subprocess
import tempfile
from pathlib import Path

log = logging.getLogger(__name__)

SOURCE = Path(__file__).with_name("native") / "start_gate.c"
TARGET = "/.hlvs-start-gate"  # where a robot container sees the gate
DIR_TARGET = "/.hlvs-start-gate.d"  # and the folder it waits in (read-only)
GO = "go"  # the file whose existence lets the robot's program run
FOLDERS = ".start-gate"  # in the match's output folder, one folder per robot (removed after)


def _cache() -> Path:
    base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return Path(base) / "hlvs" / "gate"


def compiler() -> str | None:
    """``$CC``, else ``cc`` or ``gcc`` on the path."""
    return os.environ.get("CC") or shutil.which("cc") or shutil.which("gcc")


@functools.cache
def start_gate() -> Path | None:
    """The compiled gate (built now if this source version has not been), or None when it
    cannot be built here: the reason is logged once and robots start behind holders."""
    source = SOURCE.read_bytes()
    built = _cache() / f"start_gate-{hashlib.sha256(source).hexdigest()[:16]}"
    if built.is_file() and os.access(built, os.X_OK):
        return built
    compiler_path = compiler()
    if not compiler_path:
        log.warning("no C compiler for the robots' start gate (set CC or install gcc): robots "
                    "start behind network holder containers, a slower bring-up")
        return None
    try:
        built.parent.mkdir(parents=True, exist_ok=True)
        with tempfile.TemporaryDirectory(dir=built.parent) as work:
            partial = Path(work) / built.name
            done = subprocess.run(
                [compiler_path, "-static", "-O2", "-o", str(partial), str(SOURCE)],
                capture_output=True, text=True, check=False, timeout=120,
            )  # fmt: skip
            if done.returncode != 0:
                log.warning("the robots' start gate could not be built with %s (robots start "
                            "behind network holder containers): %s", compiler_path,
                            done.stderr.strip()[-500:])
                return None
            partial.chmod(0o755)
            os.replace(partial, built)  # whole or not at all, when two matches build at once
    except (OSError, subprocess.SubprocessError) as exc:
        log.warning("the robots' start gate could not be built in %s (robots start behind "
                    "network holder containers): %s", built.parent, exc)
        return None
    return built


def folder(out_dir: Path, key: str) -> Path:
    """The empty folder robot ``key``'s gate waits in (made now, readable by any user: the
    robot's image chooses its user)."""
    folder = out_dir / FOLDERS / key
    if folder.exists():
        shutil.rmtree(folder)
    folder.mkdir(parents=True)
    folder.chmod(0o755)
    return folder


def release(folder: Path) -> None:
    """Let the gate waiting in ``folder`` run the robot's program."""
    (folder / GO).touch(mode=0o644)


def gated_launch(gate: tuple[str, ...], command: tuple[str, ...] | None,
                 image: tuple[tuple[str, ...], tuple[str, ...]]
                 ) -> tuple[tuple[str, ...], tuple[str, ...]]:
    """The entry point and command of a gated container: ``gate`` (its path in the container,
    its folder, ``--``) then the image's entry point, and ``command`` (the team's
    ``dockerCmd``) or else the image's command: what the engine would have joined."""
    entrypoint, image_command = image
    return (*gate, *entrypoint), tuple(command if command else image_command)


__all__ = ["DIR_TARGET", "TARGET", "folder", "gated_launch", "release", "start_gate"]
