"""Delivery of match logs to the teams' (and the public) SFTP or S3 targets.

``enqueue_match_logs`` turns a finished match's logs into pending sets in a local store,
``deliver_pending`` uploads them (files, then ``MANIFEST.json`` last), ``pending_status`` lists
what is waiting. Uploaders (``sftp``, ``s3``) sit behind the :class:`Uploader` protocol;
:class:`FakeUploader` stands in for them in unit tests.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from contracts import lazy_exports
from orchestrator.delivery.addresses import (
    AddressRefused,
    IPAddress,
    IPNetwork,
    address_allowed,
    literal_problem,
    networks,
    resolve,
)
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

if TYPE_CHECKING:
    from orchestrator.delivery.store import DeliveryReceipt, delivered_receipts, list_sets

__all__ = [
    "AddressRefused",
    "DeliveryFailure",
    "DeliveryOutcome",
    "DeliveryReceipt",
    "ERROR_KINDS",
    "FakeUploader",
    "FileEntry",
    "IPAddress",
    "IPNetwork",
    "KEEP_UNDELIVERED",
    "MANIFEST_NAME",
    "Opener",
    "PUBLIC_TEAM",
    "PendingSet",
    "RetryPolicy",
    "TRANSIENT_KINDS",
    "Uploader",
    "address_allowed",
    "deliver_pending",
    "deliver_set",
    "delivered_receipts",
    "enqueue_match_logs",
    "is_transient",
    "list_sets",
    "literal_problem",
    "networks",
    "open_uploader",
    "pending_status",
    "resolve",
]


if not TYPE_CHECKING:
    __getattr__, __dir__ = lazy_exports(__name__, {
        "orchestrator.delivery.store": ("DeliveryReceipt", "delivered_receipts", "list_sets"),
    })
