"""The local store of log sets waiting for delivery.

Layout::

    <store>/.lock                   held while sets are created, listed or pruned
    <store>/sets/<set_id>/.claim    held while the set is delivered or deleted
    <store>/sets/<set_id>/set.json  the set's state (team, target file, files with SHA-256,
                                    attempts, last error); rewritten atomically
    <store>/sets/<set_id>/files/    the files, as they will appear under <match_id>/<team>/
    <store>/delivered/<set_id>.json a receipt of each delivered set (match, team, target, time):
                                    a set that left the store was delivered, or else pruned

A set appears atomically (built under ``sets/.incoming-*`` and renamed), so a crash while
enqueueing never leaves a half-filled set behind that would be delivered.
"""

from __future__ import annotations

import fcntl
import hashlib
import json
import logging
import os
import shutil
import time
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import asdict, dataclass, replace
from pathlib import Path
from typing import Literal
from urllib.parse import quote

from contracts import JSONObject
from orchestrator.filelock import held

__all__ = [
    "FileEntry",
    "PendingSet",
    "DeliveryFailure",
    "claimed",
    "create_set",
    "list_sets",
    "locked",
    "remove_set",
    "save_set",
]

log = logging.getLogger(__name__)

SetKind = Literal["team", "public"]
_ID_SEPARATOR = "+"  # never in an escaped part (quote() escapes it)
_MAX_PART = 120


def set_id_of(match_id: str, team: str) -> str:
    """The set's folder name: unique by construction for each (match id, team name), however
    the names differ ("Bit Bots" and "Bit_Bots" are two sets). Each part is percent-escaped
    (injective); a part too long for a folder name is cut and ends with its SHA-256."""
    return _ID_SEPARATOR.join(_id_part(text) for text in (match_id, team))


def _id_part(text: str) -> str:
    escaped = quote(text, safe="")
    if escaped.startswith("."):  # no hidden folder, no "." or ".."
        escaped = "%2E" + escaped[1:]
    if len(escaped) > _MAX_PART:
        digest = hashlib.sha256(text.encode("utf-8", "surrogatepass")).hexdigest()
        escaped = f"{escaped[:_MAX_PART - 66]}%%{digest}"  # quote() never writes "%%"
    return escaped or "%"  # nor a lone "%"
_HASH_CHUNK = 1 << 20


@dataclass(frozen=True, slots=True)
class FileEntry:
    path: str  # relative, with "/"
    size: int
    sha256: str


@dataclass(frozen=True, slots=True)
class DeliveryFailure:
    """Why the last delivery attempt failed (DeliveryError.kind and reason)."""

    kind: str
    reason: str
    at: float  # Unix time


@dataclass(frozen=True, slots=True, kw_only=True)
class PendingSet:
    """One match's logs for one team (or the public logs) waiting in the store."""

    set_id: str
    match_id: str
    team: str
    kind: SetKind
    credentials: Path | None
    created_ns: int
    files: tuple[FileEntry, ...]
    attempts: int = 0
    last_error: DeliveryFailure | None = None
    root: Path  # the set's folder in the store

    @property
    def files_dir(self) -> Path:
        return self.root / "files"

    @property
    def total_bytes(self) -> int:
        return sum(entry.size for entry in self.files)

    def to_json(self) -> JSONObject:
        """The set as JSON (its ``set.json``, with its folder and size added)."""
        data: JSONObject = asdict(self)
        data["credentials"] = str(self.credentials) if self.credentials else None
        data["root"] = str(self.root)
        data["total_bytes"] = self.total_bytes
        return data


def sets_dir(store: Path) -> Path:
    return store / "sets"


@contextmanager
def locked(store: Path) -> Iterator[None]:
    """Hold the store's lock (an flock on ``<store>/.lock``), waiting for other holders."""
    store.mkdir(parents=True, exist_ok=True)
    with held(store / ".lock"):
        yield


@contextmanager
def claimed(pending: PendingSet) -> Iterator[bool]:
    """Take the set for delivery or removal without waiting (an flock on ``<set>/.claim``).

    Yields False when another process holds it or the set is gone; the store lock is not
    needed (and should not be held during a long upload).
    """
    try:
        handle = (pending.root / ".claim").open("a")
    except FileNotFoundError:
        yield False
        return
    with handle:
        try:
            fcntl.flock(handle, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            yield False
            return
        try:
            yield (pending.root / "set.json").is_file()
        finally:
            fcntl.flock(handle, fcntl.LOCK_UN)


def create_set(
    store: Path,
    *,
    match_id: str,
    team: str,
    kind: SetKind,
    credentials: Path | None,
    sources: list[tuple[Path, str]],
    move: bool,
) -> PendingSet:
    """Build a set from ``sources`` (local file, path inside the set). With ``move`` the files
    are moved into the store, otherwise hard-linked (copied across file systems)."""
    set_id = set_id_of(match_id, team)
    final = sets_dir(store) / set_id
    incoming = sets_dir(store) / f".incoming-{set_id}-{os.getpid()}"
    shutil.rmtree(incoming, ignore_errors=True)
    (incoming / "files").mkdir(parents=True)
    entries = []
    for source, rel in sorted(sources, key=lambda item: item[1]):
        target = incoming / "files" / rel
        target.parent.mkdir(parents=True, exist_ok=True)
        _transfer(source, target, move=move)
        entries.append(FileEntry(rel, target.stat().st_size, _sha256(target)))
    pending = PendingSet(
        set_id=set_id,
        match_id=match_id,
        team=team,
        kind=kind,
        credentials=credentials,
        created_ns=time.time_ns(),
        files=tuple(entries),
        root=final,
    )
    _write_state(incoming, pending)
    if final.exists():
        log.warning("replacing the pending log set %s (same match and team)", set_id)
        shutil.rmtree(final)
    incoming.rename(final)
    return pending


def list_sets(store: Path) -> list[PendingSet]:
    """Every set in the store, oldest first."""
    folder = sets_dir(store)
    if not folder.is_dir():
        return []
    found = []
    for child in folder.iterdir():
        if child.name.startswith(".") or not (child / "set.json").is_file():
            continue
        found.append(_read_state(child))
    return sorted(found, key=lambda s: (s.created_ns, s.set_id))


def save_set(
    pending: PendingSet, *, attempts: int, last_error: DeliveryFailure | None
) -> PendingSet:
    updated = replace(pending, attempts=attempts, last_error=last_error)
    _write_state(pending.root, updated)
    return updated


def remove_set(pending: PendingSet) -> None:
    shutil.rmtree(pending.root, ignore_errors=True)


@dataclass(frozen=True, slots=True, kw_only=True)
class DeliveryReceipt:
    """A set that was delivered (and left the store): by whom is not known, only where."""

    set_id: str
    match_id: str
    team: str
    target: str
    at: float  # Unix time


def record_delivered(pending: PendingSet, target: str) -> None:
    """Leave a receipt of a delivered set (``<store>/delivered/<set_id>.json``)."""
    folder = pending.root.parent.parent / "delivered"
    folder.mkdir(exist_ok=True)
    receipt = DeliveryReceipt(set_id=pending.set_id, match_id=pending.match_id,
                              team=pending.team, target=target, at=time.time())
    tmp = folder / f".{pending.root.name}.json.tmp"
    tmp.write_text(json.dumps(asdict(receipt)) + "\n", encoding="utf-8")
    os.replace(tmp, folder / f"{pending.root.name}.json")


def delivered_receipts(store: Path, match_id: str | None = None) -> list[DeliveryReceipt]:
    """The receipts of the sets delivered from ``store`` (of one match)."""
    folder = store / "delivered"
    if not folder.is_dir():
        return []
    found = []
    for path in sorted(folder.glob("*.json")):
        try:
            receipt = DeliveryReceipt(**json.loads(path.read_text(encoding="utf-8")))
        except (OSError, ValueError, TypeError):
            continue  # a receipt half written by a crash: the set counts as gone
        if match_id is None or receipt.match_id == match_id:
            found.append(receipt)
    return found


def _write_state(folder: Path, pending: PendingSet) -> None:
    data = pending.to_json()
    del data["root"], data["total_bytes"]
    tmp = folder / "set.json.tmp"
    tmp.write_text(json.dumps(data, indent=2) + "\n", encoding="utf-8")
    os.replace(tmp, folder / "set.json")


def _read_state(folder: Path) -> PendingSet:
    data = json.loads((folder / "set.json").read_text(encoding="utf-8"))
    error = data.get("last_error")
    return PendingSet(
        set_id=data["set_id"],
        match_id=data["match_id"],
        team=data["team"],
        kind=data["kind"],
        credentials=Path(data["credentials"]) if data.get("credentials") else None,
        created_ns=int(data["created_ns"]),
        files=tuple(FileEntry(**entry) for entry in data["files"]),
        attempts=int(data.get("attempts", 0)),
        last_error=DeliveryFailure(**error) if error else None,
        root=folder,
    )


def _transfer(source: Path, target: Path, *, move: bool) -> None:
    if move:
        shutil.move(source, target)
        return
    try:
        os.link(source, target)
    except OSError:
        shutil.copy2(source, target)


def _sha256(path: Path) -> str:
    digest = hashlib.sha256()
    with path.open("rb") as handle:
        while chunk := handle.read(_HASH_CHUNK):
            digest.update(chunk)
    return digest.hexdigest()
