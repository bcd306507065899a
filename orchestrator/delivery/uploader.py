"""The uploader boundary: one remote target (an SFTP folder or an S3 bucket prefix).

Adapters (``sftp.py``, ``s3.py``) translate their library's errors into
:class:`~orchestrator.errors.DeliveryError` with a ``kind``; :data:`TRANSIENT_KINDS` are retried,
every other kind is something the team has to fix. :class:`FakeUploader` keeps files in memory
for unit tests and can be told to fail.
"""

from __future__ import annotations

import hashlib
from collections import deque
from dataclasses import dataclass, field
from pathlib import Path
from typing import Protocol

from orchestrator.errors import DeliveryError

__all__ = [
    "ERROR_KINDS",
    "FakeUploader",
    "TRANSIENT_KINDS",
    "Uploader",
    "is_transient",
]

#: Every DeliveryError.kind raised by this package and what the team can do about it.
ERROR_KINDS = {
    "auth": "the server rejected the user name, password, key or access id/secret",
    "host_key": "the server's host key does not match the pinned key or known_hosts",
    "bucket": "the bucket does not exist",
    "access_denied": "the account may not write there",
    "path": "the remote folder cannot be created or written",
    "unreachable": "no server answers at that address",
    "address": "the target's address is not one the league delivers to (not public)",
    "transient": "the connection broke or the server had an internal error",
    "config": "the credentials file is missing or invalid",
    "store": "a file of the set is missing or changed in the local store",
}
TRANSIENT_KINDS = frozenset({"transient", "unreachable"})


def is_transient(error: DeliveryError) -> bool:
    """True when retrying later may succeed without the team changing anything."""
    return error.kind in TRANSIENT_KINDS


class Uploader(Protocol):
    """One open connection to a delivery target. Paths are relative to the target's base
    folder (SFTP ``path``, S3 ``prefix``) and use ``/``."""

    @property
    def target(self) -> str:
        """Where files go, without secrets (for messages and logs)."""
        ...

    def upload(self, local_path: Path, remote_rel_path: str) -> None:
        """Copy one file; the remote file appears complete or not at all."""
        ...

    def exists(self, remote_rel_path: str, size: int) -> bool:
        """True if the remote file exists with exactly ``size`` bytes."""
        ...

    def close(self) -> None: ...


@dataclass
class FakeUploader:
    """An in-memory target. ``failures`` is a queue of errors raised by the next calls to
    ``upload`` (one error per call); ``calls`` records every upload."""

    target: str = "fake://target"
    files: dict[str, bytes] = field(default_factory=dict)
    failures: deque[DeliveryError] = field(default_factory=deque)
    calls: list[str] = field(default_factory=list)
    closed: bool = False

    def upload(self, local_path: Path, remote_rel_path: str) -> None:
        self.calls.append(remote_rel_path)
        if self.failures:
            raise self.failures.popleft()
        self.files[remote_rel_path] = local_path.read_bytes()

    def exists(self, remote_rel_path: str, size: int) -> bool:
        data = self.files.get(remote_rel_path)
        return data is not None and len(data) == size

    def close(self) -> None:
        self.closed = True

    def sha256(self, remote_rel_path: str) -> str:
        return hashlib.sha256(self.files[remote_rel_path]).hexdigest()
