"""Delivery of match logs to the teams' (and the public) SFTP or S3 targets.

``enqueue_match_logs`` turns a finished match's logs into pending sets in a local store,
``deliver_pending`` uploads them (files, then ``MANIFEST.json`` last), ``pending_status`` lists
what is waiting. Uploaders (``sftp``, ``s3``) sit behind the :class:`Uploader` protocol;
:class:`FakeUploader` stands in for them in unit tests.
"""

from __future__ import annotations

from orchestrator.delivery.deliver import (
    MANIFEST_NAME,
    DeliveryOutcome,
    Opener,
    RetryPolicy,
    deliver_pending,
    deliver_set,
    pending_status,
)
from orchestrator.delivery.enqueue import KEEP_UNDELIVERED, PUBLIC_TEAM, enqueue_match_logs
from orchestrator.delivery.store import DeliveryFailure, FileEntry, PendingSet
from orchestrator.delivery.targets import open_uploader
from orchestrator.delivery.uploader import (
    ERROR_KINDS,
    TRANSIENT_KINDS,
    FakeUploader,
    Uploader,
    is_transient,
)

__all__ = [
    "deliver_pending",
    "deliver_set",
    "DeliveryOutcome",
    "enqueue_match_logs",
    "ERROR_KINDS",
    "FakeUploader",
    "FileEntry",
    "is_transient",
    "KEEP_UNDELIVERED",
    "MANIFEST_NAME",
    "open_uploader",
    "Opener",
    "pending_status",
    "PendingSet",
    "PUBLIC_TEAM",
    "RetryPolicy",
    "DeliveryFailure",
    "TRANSIENT_KINDS",
    "Uploader",
]
