"""A process named so that another process sharing the machine (or only its Docker engine) can
tell, without mistakes, that it ended: its host, its pid namespace, its pid and its start time.

A pid alone is not enough: a reused pid looks alive, and a process in another pid namespace (an
orchestrator in a container, a job of a cluster whose nodes share this engine) has a pid that
may be free, or someone else's, here. :func:`ended` is therefore True only where this process
can see the owner's namespace; anything it cannot judge is alive.
"""

from __future__ import annotations

import os
import socket
from pathlib import Path


def start_time(pid: int) -> str | None:
    """The start time of process ``pid`` (field 22 of /proc/PID/stat, clock ticks since boot),
    None when it is gone or has exited and waits to be reaped."""
    try:
        fields = Path(f"/proc/{pid}/stat").read_text().rpartition(")")[2].split()
    except OSError:
        return None
    return None if fields[0] == "Z" else fields[19]


def pid_namespace() -> str:
    """The inode of this process's pid namespace ("" where /proc cannot tell)."""
    try:
        return str(os.stat("/proc/self/ns/pid").st_ino)
    except OSError:
        return ""


def ended(*, hostname: str, namespace: str, pid: int, start: str) -> bool:
    """True only when the process (``hostname``, pid ``namespace``, ``pid``, ``start``) ran
    where this process can see it and has ended: same host, same pid namespace, and no process
    with that pid and start time. An empty ``namespace`` or ``start`` cannot be judged."""
    if hostname != socket.gethostname() or not start:
        return False
    if not namespace or namespace != pid_namespace():
        return False
    return start_time(pid) != start
