"""Signed webhooks: how the league's programs (the submission service, the tournament's
scheduler) sign a delivery and how a receiver checks one.

Headers of every delivery::

    X-HLVS-Event: submission.finished
    X-HLVS-Delivery: <id, unique per notification; the same on every retry>
    X-HLVS-Timestamp: <unix seconds of this attempt>
    X-HLVS-Signature: sha256=<hex HMAC-SHA256(secret, "<timestamp>.<delivery>.<body>")>

A receiver recomputes the signature with the secret it set (``PATCH /v1/team`` for the service;
``--notify-webhook-secret-file`` for ``hlvs schedule run``), refuses a
timestamp older than a few minutes and a delivery id it has already accepted (:func:`verify`
does all three), so a captured request cannot be replayed.
"""

from __future__ import annotations

import hashlib
import hmac
import time
from collections.abc import Callable, Mapping


class WebhookRejected(Exception):
    """A delivery that must not be trusted; ``reason``: missing, signature, stale, replayed."""

    def __init__(self, reason: str, message: str) -> None:
        self.reason = reason
        super().__init__(message)


def _mac(secret: str, timestamp: str, delivery_id: str, body: bytes) -> str:
    signed = timestamp.encode() + b"." + delivery_id.encode() + b"." + body
    return hmac.new(secret.encode(), signed, hashlib.sha256).hexdigest()


def sign(secret: str, *, delivery_id: str, event: str, body: bytes,
         timestamp: int | None = None) -> dict[str, str]:
    stamp = str(int(time.time()) if timestamp is None else timestamp)
    return {
        "Content-Type": "application/json",
        "X-HLVS-Event": event,
        "X-HLVS-Delivery": delivery_id,
        "X-HLVS-Timestamp": stamp,
        "X-HLVS-Signature": "sha256=" + _mac(secret, stamp, delivery_id, body),
    }


def verify(secret: str, headers: Mapping[str, str], body: bytes, *,
           seen: Callable[[str], bool], tolerance_s: float = 300.0,
           clock: Callable[[], float] = time.time) -> str:
    """Check a delivery; returns its delivery id. ``seen(id)`` records an id and returns
    whether it was already recorded (a set's check-and-add, or a database insert)."""
    lower = {k.lower(): v for k, v in headers.items()}
    delivery = lower.get("x-hlvs-delivery")
    stamp = lower.get("x-hlvs-timestamp")
    signature = lower.get("x-hlvs-signature", "")
    if not delivery or not stamp or not signature.startswith("sha256="):
        raise WebhookRejected("missing", "missing X-HLVS-Delivery, X-HLVS-Timestamp or "
                              "X-HLVS-Signature (sha256=...) header")
    expected = _mac(secret, stamp, delivery, body)
    if not hmac.compare_digest(expected, signature.removeprefix("sha256=")):
        raise WebhookRejected("signature", f"delivery {delivery}: the signature does not match "
                              "the body (wrong secret or altered body)")
    try:
        age = clock() - int(stamp)
    except ValueError:
        raise WebhookRejected("stale", f"delivery {delivery}: timestamp {stamp!r} is not "
                              "unix seconds") from None
    if abs(age) > tolerance_s:
        raise WebhookRejected("stale", f"delivery {delivery}: timestamp is {age:.0f} s old "
                              f"(at most {tolerance_s:.0f} s accepted)")
    if seen(delivery):
        raise WebhookRejected("replayed", f"delivery {delivery} was already accepted once")
    return delivery


__all__ = ["WebhookRejected", "sign", "verify"]
