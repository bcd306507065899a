"""Delivering log sets: upload pending sets and report their status.

A set is uploaded under ``<match_id>/<team>/`` of its target: every file not already there with
the same size, then ``MANIFEST.json`` (names, sizes, SHA-256) last, so a manifest on the server
means the set is complete. Transient failures (connection lost, timeouts, 5xx, server not
answering) are retried with exponential backoff, reconnecting each time; anything else fails at
once. A failed set stays in the store with its typed cause; a delivered set is deleted.
"""

from __future__ import annotations

import functools
import json
import logging
import time
from collections.abc import Callable
from dataclasses import dataclass, fields
from pathlib import Path
from typing import TypeVar

from contracts import JSONObject, to_data
from orchestrator.config.credentials import Credentials, load_credentials
from orchestrator.console import NullProgress, Progress, Task
from orchestrator.delivery import store as st
from orchestrator.delivery.targets import open_uploader
from orchestrator.delivery.uploader import Uploader, is_transient
from orchestrator.errors import ConfigError, DeliveryError

__all__ = [
    "MANIFEST_NAME",
    "DeliveryOutcome",
    "Opener",
    "RetryPolicy",
    "deliver_pending",
    "deliver_set",
    "pending_status",
]

log = logging.getLogger(__name__)

MANIFEST_NAME = "MANIFEST.json"

Opener = Callable[[Credentials, str], Uploader]  # (credentials, team) -> open uploader
T = TypeVar("T")


@dataclass(frozen=True, slots=True, kw_only=True)
class RetryPolicy:
    """Exponential backoff for transient errors: ``attempts`` tries per operation."""

    attempts: int = 4
    initial_delay_s: float = 1.0
    factor: float = 2.0
    max_delay_s: float = 30.0


@dataclass(frozen=True, slots=True, kw_only=True)
class DeliveryOutcome:
    set_id: str
    match_id: str
    team: str
    target: str
    delivered: bool
    uploaded_files: int = 0
    skipped_files: int = 0
    uploaded_bytes: int = 0
    seconds: float = 0.0
    error: DeliveryError | None = None

    def to_json(self) -> JSONObject:
        """The outcome as JSON (``hlvs logs deliver --json``): its fields, the error as its
        kind and reason."""
        data: JSONObject = {
            f.name: to_data(getattr(self, f.name)) for f in fields(self) if f.name != "error"
        }
        data["error_kind"] = self.error.kind if self.error else None
        data["error_reason"] = self.error.reason if self.error else None
        return data


def deliver_pending(
    store: Path,
    *,
    team: str | None = None,
    match_id: str | None = None,
    retry: RetryPolicy | None = None,
    opener: Opener | None = None,
    sleep: Callable[[float], None] = time.sleep,
    progress: Progress | None = None,
) -> list[DeliveryOutcome]:
    """Try every pending set (of ``team`` and of ``match_id`` only, if given), oldest first."""
    outcomes = []
    with st.locked(store):
        candidates = [
            s for s in st.list_sets(store)
            if (team is None or s.team == team) and (match_id is None or s.match_id == match_id)
        ]
    for pending in candidates:
        with st.claimed(pending) as mine:
            if not mine:
                log.info(
                    "match %s: the logs of %s are being delivered by another process",
                    pending.match_id,
                    pending.team,
                )
                continue
            outcomes.append(
                deliver_set(pending, retry=retry or RetryPolicy(), opener=opener, sleep=sleep,
                            progress=progress)
            )
    return outcomes


def pending_status(store: Path) -> list[st.PendingSet]:
    """The sets waiting in the store, oldest first, with attempts and the last error."""
    return st.list_sets(store)


def deliver_set(
    pending: st.PendingSet,
    *,
    retry: RetryPolicy,
    opener: Opener | None = None,
    sleep: Callable[[float], None] = time.sleep,
    progress: Progress | None = None,
) -> DeliveryOutcome:
    """Upload one set; on success delete it locally, on failure record the cause in it.

    The caller holds the set's claim (:func:`store.claimed`), as :func:`deliver_pending` does.
    """
    started = time.monotonic()
    target = str(pending.credentials) if pending.credentials else "(no credentials)"
    session: _Session | None = None
    counts = _Counts()
    total_bytes = sum(entry.size for entry in pending.files)
    task = (progress or NullProgress()).add(
        f"upload {pending.match_id} {pending.team}", total=total_bytes, unit="B"
    )
    try:
        credentials = _credentials_of(pending)
        target = credentials.describe()
        session = _Session(credentials, pending.team, opener or open_uploader, retry, sleep)
        _upload_set(pending, session, task, counts)
    except DeliveryError as exc:
        task.finish("failed")
        error = DeliveryError(team=pending.team, target=target, kind=exc.kind, reason=exc.reason)
        st.save_set(
            pending,
            attempts=pending.attempts + 1,
            last_error=st.DeliveryFailure(error.kind, error.reason, time.time()),
        )
        log.warning("match %s: %s", pending.match_id, error)
        return counts.outcome(pending, target, time.monotonic() - started, error=error)
    finally:
        if session is not None:
            session.close()
    task.finish()
    st.remove_set(pending)
    st.record_delivered(pending, target)
    seconds = time.monotonic() - started
    log.info(
        "match %s: delivered the logs of %s to %s (%d files uploaded, %d already there, "
        "%.1f MB in %.1f s)",
        pending.match_id,
        pending.team,
        target,
        counts.uploaded,
        counts.skipped,
        counts.uploaded_bytes / 1e6,
        seconds,
    )
    return counts.outcome(pending, target, seconds)


@dataclass(slots=True)
class _Counts:
    """What a delivery has done so far: kept when it fails half way."""

    uploaded: int = 0
    skipped: int = 0  # already there with the same size
    uploaded_bytes: int = 0

    def outcome(
        self,
        pending: st.PendingSet,
        target: str,
        seconds: float,
        *,
        error: DeliveryError | None = None,
    ) -> DeliveryOutcome:
        """The set's outcome: delivered unless ``error``."""
        return DeliveryOutcome(
            set_id=pending.set_id,
            match_id=pending.match_id,
            team=pending.team,
            target=target,
            delivered=error is None,
            uploaded_files=self.uploaded,
            skipped_files=self.skipped,
            uploaded_bytes=self.uploaded_bytes,
            seconds=seconds,
            error=error,
        )


def _upload_set(pending: st.PendingSet, session: _Session, task: Task, counts: _Counts) -> None:
    """Upload the set's files that are not there yet (same size), then its manifest, last:
    a folder with the manifest is complete. Raises :class:`DeliveryError`."""
    base = f"{_folder_name(pending.match_id)}/{_folder_name(pending.team)}"
    done_bytes = 0
    for entry in pending.files:
        remote = f"{base}/{entry.path}"
        local = pending.files_dir / entry.path
        done_bytes += entry.size
        if session.run(functools.partial(_exists, remote=remote, size=entry.size)):
            counts.skipped += 1
            task.update(completed=done_bytes)
            continue
        _check_local(pending, local, entry.size)
        session.run(functools.partial(_upload, local=local, remote=remote))
        counts.uploaded += 1
        counts.uploaded_bytes += entry.size
        task.update(completed=done_bytes)
    manifest = _write_manifest(pending)
    session.run(functools.partial(_upload, local=manifest, remote=f"{base}/{MANIFEST_NAME}"))


class _Session:
    """An uploader that reconnects and retries transient failures with backoff."""

    def __init__(
        self,
        credentials: Credentials,
        team: str,
        opener: Opener,
        retry: RetryPolicy,
        sleep: Callable[[float], None],
    ) -> None:
        self._credentials = credentials
        self._team = team
        self._opener = opener
        self._retry = retry
        self._sleep = sleep
        self._uploader: Uploader | None = None

    def run(self, action: Callable[[Uploader], T]) -> T:
        delay = self._retry.initial_delay_s
        for attempt in range(1, self._retry.attempts + 1):
            try:
                if self._uploader is None:
                    self._uploader = self._opener(self._credentials, self._team)
                return action(self._uploader)
            except DeliveryError as exc:
                if not is_transient(exc) or attempt >= self._retry.attempts:
                    raise
                log.warning(
                    "%s (attempt %d of %d, retrying in %.1f s)",
                    exc,
                    attempt,
                    self._retry.attempts,
                    delay,
                )
                self.close()
                self._sleep(delay)
                delay = min(delay * self._retry.factor, self._retry.max_delay_s)
        raise AssertionError("unreachable: the loop returns or raises")

    def close(self) -> None:
        if self._uploader is not None:
            uploader, self._uploader = self._uploader, None
            uploader.close()


def _folder_name(name: str) -> str:
    """One remote path component: no separators, no dot-only names."""
    safe = name.replace("/", "_").replace("\\", "_").strip()
    return safe if safe.strip(".") else "_"


def _exists(uploader: Uploader, *, remote: str, size: int) -> bool:
    return uploader.exists(remote, size)


def _upload(uploader: Uploader, *, local: Path, remote: str) -> None:
    uploader.upload(local, remote)


def _check_local(pending: st.PendingSet, local: Path, size: int) -> None:
    try:
        actual = local.stat().st_size
    except OSError as exc:
        reason = f"{local} is missing from the local store: {exc.strerror}"
        raise DeliveryError(
            team=pending.team, target="(local store)", kind="store", reason=reason
        ) from exc
    if actual != size:
        reason = f"{local} changed in the local store ({actual} bytes, {size} when queued)"
        raise DeliveryError(team=pending.team, target="(local store)", kind="store", reason=reason)


def _credentials_of(pending: st.PendingSet) -> Credentials:
    if pending.credentials is None:
        raise DeliveryError(
            team=pending.team,
            target="(none)",
            kind="config",
            reason="the team gave no credentials.json",
        )
    try:
        return load_credentials(pending.credentials)
    except ConfigError as exc:
        raise DeliveryError(
            team=pending.team, target=str(pending.credentials), kind="config", reason=str(exc)
        ) from exc


def _write_manifest(pending: st.PendingSet) -> Path:
    manifest = {
        "match_id": pending.match_id,
        "team": pending.team,
        "files": [{"path": e.path, "size": e.size, "sha256": e.sha256} for e in pending.files],
    }
    path = pending.root / MANIFEST_NAME
    path.write_text(json.dumps(manifest, indent=2) + "\n", encoding="utf-8")
    return path
