"""Signed webhooks of the service: the signing and checking of :mod:`contracts.webhooks`."""

from __future__ import annotations

from contracts import webhooks as _contract

WebhookRejected = _contract.WebhookRejected
sign = _contract.sign
verify = _contract.verify

__all__ = ["WebhookRejected", "sign", "verify"]
