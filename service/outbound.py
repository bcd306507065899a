"""Requests the service sends to an address a team chose (its webhook): public addresses only.

A team's URL may not reach the league's own networks: loopback, private, link-local (cloud
metadata at 169.254.169.254), shared, multicast and reserved addresses are refused, unless the
operator allows a network (``HLVS_SERVICE_WEBHOOK_ALLOW``). The URL is checked when it is set
(:func:`check_url`) and again at every delivery (:func:`post`): the name is resolved, every
address it resolves to must be allowed, and the request goes to the address that was checked
(the name is kept for the Host header and TLS), so a name that resolves to a public address
when checked and to a private one a moment later (DNS rebinding) reaches nothing.

The rules are those of :mod:`orchestrator.delivery.addresses`, which a team's log target
obeys too (``HLVS_SERVICE_LOG_TARGET_ALLOW``, :func:`log_target_networks`).
"""

from __future__ import annotations

from collections.abc import Mapping

import httpx

from orchestrator.delivery import (
    AddressRefused,
    IPAddress,
    IPNetwork,
    address_allowed,
    literal_problem,
)
from orchestrator.delivery import resolve as _resolve
from service.errors import InvalidInput
from service.settings import (
    LOG_TARGET_ALLOW_SETTING,
    Settings,
    log_target_networks,
    webhook_networks,
)
from service.settings import WEBHOOK_ALLOW_SETTING as ALLOW_SETTING

Refused = AddressRefused


def allowed_networks(settings: Settings) -> tuple[IPNetwork, ...]:
    return webhook_networks(settings)


def allowed_log_networks(settings: Settings) -> tuple[IPNetwork, ...]:
    return log_target_networks(settings)


def check_url(url: str, allowed: tuple[IPNetwork, ...], *, field: str) -> None:
    """At the time a URL is set: http(s), and a host that is not a refused address literal
    or ``localhost`` (a name is checked again at every delivery)."""
    parsed = httpx.URL(url)
    problem = None
    if parsed.scheme not in ("http", "https"):
        problem = f"scheme {parsed.scheme!r} is not accepted"
    else:
        problem = literal_problem(parsed.host, allowed, ALLOW_SETTING)
    if problem is not None:
        raise InvalidInput(f"{field}: {problem}", problems=[{
            "where": "body", "pointer": field, "message": problem,
            "expected": "an http(s) URL of a public address"}])


def resolve(host: str, port: int, allowed: tuple[IPNetwork, ...]) -> IPAddress:
    """The address to connect to for ``host``; :class:`Refused` when any address the name
    resolves to is not allowed (or it resolves to none)."""
    return _resolve(host, port, allowed, ALLOW_SETTING)


def post(client: httpx.Client, url: str, *, content: bytes, headers: Mapping[str, str],
         allowed: tuple[IPNetwork, ...]) -> httpx.Response:
    """POST to ``url`` at the address checked just now (:class:`Refused` when not allowed)."""
    parsed = httpx.URL(url)
    if parsed.scheme not in ("http", "https"):
        raise Refused(f"scheme {parsed.scheme!r} is not accepted")
    port = parsed.port or (443 if parsed.scheme == "https" else 80)
    address = resolve(parsed.host, port, allowed)
    pinned = parsed.copy_with(host=str(address))
    extensions = {"sni_hostname": parsed.host} if parsed.scheme == "https" else {}
    return client.post(pinned, content=content,
                       headers={**headers, "Host": parsed.netloc.decode("ascii")},
                       extensions=extensions)


__all__ = ["ALLOW_SETTING", "LOG_TARGET_ALLOW_SETTING", "Refused", "address_allowed",
           "allowed_log_networks", "allowed_networks", "check_url", "post", "resolve"]
