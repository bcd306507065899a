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

if TYPE_CHECKING:
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
    from orchestrator.delivery.store import (
        DeliveryFailure,
        DeliveryReceipt,
        FileEntry,
        PendingSet,
        delivered_receipts,
        list_sets,
    )
    from orchestrator.delivery.targets import open_uploader
    from orchestrator.delivery.uploader import (
        ERROR_KINDS,
        TRANSIENT_KINDS,
        FakeUploader,
        Uploader,
        is_transient,
    )

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


# The address rules are light (the service's settings read them while the command line builds its
# parser); the rest loads the configuration and the uploaders, so it is imported when first used.
if not TYPE_CHECKING:
    __getattr__, __dir__ = lazy_exports(__name__, {
        "orchestrator.delivery.deliver": (
            "MANIFEST_NAME", "DeliveryOutcome", "Opener", "RetryPolicy", "deliver_pending",
            "deliver_set", "pending_status",
        ),
        "orchestrator.delivery.enqueue": ("KEEP_UNDELIVERED", "PUBLIC_TEAM", "enqueue_match_logs"),
        "orchestrator.delivery.store": (
            "DeliveryFailure", "DeliveryReceipt", "FileEntry", "PendingSet", "delivered_receipts",
            "list_sets",
        ),
        "orchestrator.delivery.targets": ("open_uploader",),
        "orchestrator.delivery.uploader": (
            "ERROR_KINDS", "TRANSIENT_KINDS", "FakeUploader", "Uploader", "is_transient",
        ),
    })
