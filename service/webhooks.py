"""Signed webhooks of the service: the signing and checking of :mod:`contracts.webhooks`."""

from __future__ import annotations

from contracts.webhooks import WebhookRejected, sign, verify

__all__ = ["WebhookRejected", "sign", "verify"]
