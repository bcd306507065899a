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

The gate is built once per source version with the machine's C compiler, statically, into the
user's cache (:mod:`simulator.native_build`); without a compiler or a static C library the
robots start behind holders as before (said once in the log).
"""

from __future__ import annotations

import functools
import logging
import shutil
from pathlib import Path

from simulator import NativeBuildError, build_native

log = logging.getLogger(__name__)

SOURCE = Path(__file__).with_name("native") / "start_gate.c"
TARGET = "/.hlvs-start-gate"  # where a robot container sees the gate
DIR_TARGET = "/.hlvs-start-gate.d"  # and the folder it waits in (read-only)
GO = "go"  # the file whose existence lets the robot's program run
FOLDERS = ".start-gate"  # in the match's output folder, one folder per robot (removed after)


@functools.cache
def start_gate() -> Path | None:
    """The compiled gate (built now if this source version has not been), or None when it
    cannot be built here: the reason is logged once and robots start behind holders."""
    try:
        return build_native(SOURCE, "gate", ("-static", "-O2"))
    except NativeBuildError as exc:
        log.warning("the robots' start gate cannot be built (robots start behind network holder "
                    "containers, a slower bring-up): %s", exc.reason[-500:])
        return None


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
