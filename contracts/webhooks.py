"""Signed webhooks: how the league's programs (the submission service, the tournament's
scheduler) sign a delivery and how a receiver checks one.

Headers of every delivery::

    X-HLVS-Event: submission.finished
    X-HLVS-Delivery: <id, unique per notification; the same on every retry>
    X-HLVS-Timestamp: <unix seconds of this attempt>
    X-HLVS-Signature-V2: sha256=<hex HMAC-SHA256(secret, N(timestamp) N(delivery) N(body))>
    X-HLVS-Signature: sha256=<hex HMAC-SHA256(secret, "<timestamp>.<delivery>.<body>")>

``N(x)`` is ``x`` length-delimited as a netstring: ``b"<length in bytes>:" + x + b","``. Each
field's length is part of what is signed, so no byte can move from one field to another: the
first form (``X-HLVS-Signature``, kept for a transition) joined the fields with ``.``, and a
captured delivery verified under a new id that took the start of the body (``d1.{`` and the
body cut after it).

Transition: the programs send both headers. :func:`verify` checks ``X-HLVS-Signature-V2`` when a
delivery has it; a delivery with only the first form is accepted while ``legacy`` is true (the
default for now) and only when its id and timestamp cannot hold a ``.`` (an id of letters,
digits, ``-`` and ``_``, a timestamp of digits), which makes that form unambiguous too. Receivers
move to ``X-HLVS-Signature-V2`` (this module's :func:`verify` already does); a later release
stops sending the first form and makes ``legacy=False`` the default.

A receiver recomputes the signature with the secret it set (``PATCH /v1/team`` for the service;
``--notify-webhook-secret-file`` for ``hlvs schedule run``), refuses a
timestamp older than a few minutes and a delivery id it has already accepted (:func:`verify`
does all three), so a captured request cannot be replayed.
"""

from __future__ import annotations

import hashlib
import hmac
import re
import time
from collections.abc import Callable, Mapping

SIGNATURE = "X-HLVS-Signature-V2"
LEGACY_SIGNATURE = "X-HLVS-Signature"
_PLAIN_ID = re.compile(r"[A-Za-z0-9_-]{1,128}")
_PLAIN_STAMP = re.compile(r"[0-9]{1,12}")


class WebhookRejected(Exception):
    """A delivery that must not be trusted; ``reason``: missing, signature, stale, replayed."""

    def __init__(self, reason: str, message: str) -> None:
        self.reason = reason
        super().__init__(message)


def _netstring(data: bytes) -> bytes:
    return str(len(data)).encode() + b":" + data + b","


def _mac(secret: str, timestamp: str, delivery_id: str, body: bytes) -> str:
    signed = (_netstring(timestamp.encode()) + _netstring(delivery_id.encode())
              + _netstring(body))
    return hmac.new(secret.encode(), signed, hashlib.sha256).hexdigest()


def _legacy_mac(secret: str, timestamp: str, delivery_id: str, body: bytes) -> str:
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
        SIGNATURE: "sha256=" + _mac(secret, stamp, delivery_id, body),
        LEGACY_SIGNATURE: "sha256=" + _legacy_mac(secret, stamp, delivery_id, body),
    }


def verify(secret: str, headers: Mapping[str, str], body: bytes, *,
           seen: Callable[[str], bool], tolerance_s: float = 300.0,
           clock: Callable[[], float] = time.time, legacy: bool = True) -> str:
    """Check a delivery; returns its delivery id. ``seen(id)`` records an id and returns
    whether it was already recorded (a set's check-and-add, or a database insert).
    ``legacy``: accept a delivery signed in the first form only (see the module)."""
    lower = {k.lower(): v for k, v in headers.items()}
    delivery = lower.get("x-hlvs-delivery")
    stamp = lower.get("x-hlvs-timestamp")
    signature = lower.get(SIGNATURE.lower(), "")
    old = lower.get(LEGACY_SIGNATURE.lower(), "")
    if not delivery or not stamp or not (signature.startswith("sha256=") or (
            legacy and old.startswith("sha256="))):
        raise WebhookRejected("missing", f"missing X-HLVS-Delivery, X-HLVS-Timestamp or "
                              f"{SIGNATURE} (sha256=...) header")
    if signature:
        valid = signature.startswith("sha256=") and hmac.compare_digest(
            _mac(secret, stamp, delivery, body), signature.removeprefix("sha256="))
    else:  # the first form: only where no field can hold the separator
        valid = bool(_PLAIN_ID.fullmatch(delivery) and _PLAIN_STAMP.fullmatch(stamp)) and \
            hmac.compare_digest(_legacy_mac(secret, stamp, delivery, body),
                                old.removeprefix("sha256="))
    if not valid:
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


__all__ = ["LEGACY_SIGNATURE", "SIGNATURE", "WebhookRejected", "sign", "verify"]
