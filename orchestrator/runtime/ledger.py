"""What this runner created: one empty file per container and network id.

Cleanup removes only objects found here. Labels alone do not prove that the runner made an
object: a team's image can carry our labels, and a container started from it outside the runner
(to look at it, say) carries them too. The ledger lives in ``$HLVS_STATE_DIR/created/`` (0700),
next to the run records; an id is entered when the engine has created the object and removed
when the runner removes it.

The object's name is entered before the engine is asked to create it (``container.NAME``,
``network.NAME``): a runner killed while the engine creates an object (the request sent, the
answer not read) leaves an object whose id it never learnt, and cleanup still knows it as the
runner's by its name (names are unique on an engine, and only the runner makes ours).
"""

from __future__ import annotations

import contextlib
import logging
import os
import re
from pathlib import Path

from orchestrator.paths import state_dir

log = logging.getLogger(__name__)

_ID = re.compile(r"[0-9a-f]{12,64}")
_NAME = re.compile(r"[A-Za-z0-9][A-Za-z0-9_.-]{0,200}")
_KINDS = ("container", "network")


def ledger_dir() -> Path:
    return state_dir() / "created"


def _enter(entry: Path, what: str) -> None:
    """Make the empty file ``entry`` in the ledger (best effort: a state folder that cannot be
    written only means that cleanup will not remove the object, and says so)."""
    try:
        entry.parent.mkdir(parents=True, exist_ok=True, mode=0o700)
        os.close(os.open(entry, os.O_WRONLY | os.O_CREAT | os.O_NOFOLLOW, 0o600))
    except OSError as exc:
        log.warning("cannot record %s in %s (cleanup will leave it): %s", what, entry.parent,
                    exc)


def note(object_id: str) -> None:
    """Enter ``object_id`` (best effort, see :func:`_enter`)."""
    if _ID.fullmatch(object_id):
        _enter(ledger_dir() / object_id, object_id[:12])


def created(object_id: str) -> bool:
    """True when this runner created ``object_id`` and has not removed it yet."""
    return bool(_ID.fullmatch(object_id)) and (ledger_dir() / object_id).is_file()


def forget(object_id: str) -> None:
    if _ID.fullmatch(object_id):
        with contextlib.suppress(OSError):
            (ledger_dir() / object_id).unlink()


def _name_entry(kind: str, name: str) -> Path | None:
    if kind not in _KINDS or not _NAME.fullmatch(name):
        return None
    return ledger_dir() / f"{kind}.{name}"


def intend(kind: str, name: str) -> None:
    """Enter the name of a ``kind`` object ("container" or "network") about to be created
    (best effort, see :func:`_enter`)."""
    entry = _name_entry(kind, name)
    if entry is not None:
        _enter(entry, f"{kind} {name}")


def intended(kind: str, name: str) -> bool:
    """True when this runner asked the engine to create a ``kind`` object named ``name`` and
    has not removed it yet."""
    entry = _name_entry(kind, name)
    return entry is not None and entry.is_file()


def forget_name(kind: str, name: str) -> None:
    entry = _name_entry(kind, name)
    if entry is not None:
        with contextlib.suppress(OSError):
            entry.unlink()


__all__ = ["created", "forget", "forget_name", "intend", "intended", "ledger_dir", "note"]
