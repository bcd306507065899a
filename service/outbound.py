"""Requests the service sends to an address a team chose (its webhook): public addresses only.

A team's URL may not reach the league's own networks: loopback, private, link-local (cloud
metadata at 169.254.169.254), shared, multicast and reserved addresses are refused, unless the
operator allows a network (``HLVS_SERVICE_WEBHOOK_ALLOW``). The URL is checked when it is set
(:func:`check_url`) and again at every delivery (:func:`post`): the name is resolved, every
address it resolves to must be allowed, and the request goes to the address that was checked
(the name is kept for the Host header and TLS), so a name that resolves to a public address
when checked and to a private one a moment later (DNS rebinding) reaches nothing.
"""

from __future__ import annotations

import ipaddress
import socket
from collections.abc import Mapping

import httpx

from service.errors import InvalidInput
from service.settings import IPNetwork, Settings, webhook_networks

IPAddress = ipaddress.IPv4Address | ipaddress.IPv6Address
ALLOW_SETTING = "HLVS_SERVICE_WEBHOOK_ALLOW"


class Refused(ValueError):
    """The address is not one the service may send to."""


def allowed_networks(settings: Settings) -> tuple[IPNetwork, ...]:
    return webhook_networks(settings)


def address_allowed(address: IPAddress, allowed: tuple[IPNetwork, ...]) -> bool:
    """A public unicast address, or one in a network the operator allows."""
    if isinstance(address, ipaddress.IPv6Address) and address.ipv4_mapped is not None:
        address = address.ipv4_mapped
    if any(address.version == n.version and address in n for n in allowed):
        return True
    return address.is_global and not address.is_multicast


def _refusal(host: str, address: IPAddress) -> str:
    return (f"{host} is {address}, not a public address (the league's own networks are not "
            f"reachable; an operator may allow a network with {ALLOW_SETTING})")


def check_url(url: str, allowed: tuple[IPNetwork, ...], *, field: str) -> None:
    """At the time a URL is set: http(s), and a host that is not a refused address literal
    or ``localhost`` (a name is checked again at every delivery)."""
    parsed = httpx.URL(url)
    problem = None
    if parsed.scheme not in ("http", "https"):
        problem = f"scheme {parsed.scheme!r} is not accepted"
    else:
        host = parsed.host.lower().rstrip(".")
        try:
            address: IPAddress | None = ipaddress.ip_address(host)
        except ValueError:
            address = None
        if address is not None and not address_allowed(address, allowed):
            problem = _refusal(host, address)
        elif address is None and (host == "localhost" or host.endswith(".localhost")):
            problem = f"{host} is this host, not a public address"
    if problem is not None:
        raise InvalidInput(f"{field}: {problem}", problems=[{
            "where": "body", "pointer": field, "message": problem,
            "expected": "an http(s) URL of a public address"}])


def resolve(host: str, port: int, allowed: tuple[IPNetwork, ...]) -> IPAddress:
    """The address to connect to for ``host``; :class:`Refused` when any address the name
    resolves to is not allowed (or it resolves to none)."""
    try:
        infos = socket.getaddrinfo(host, port, type=socket.SOCK_STREAM)
    except (OSError, UnicodeError) as exc:
        raise Refused(f"{host} does not resolve: {exc}") from None
    addresses: list[IPAddress] = []
    for info in infos:
        address = ipaddress.ip_address(str(info[4][0]).split("%")[0])
        if address not in addresses:
            addresses.append(address)
    if not addresses:
        raise Refused(f"{host} resolves to no address")
    for address in addresses:
        if not address_allowed(address, allowed):
            raise Refused(_refusal(host, address))
    return addresses[0]


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


__all__ = ["ALLOW_SETTING", "Refused", "address_allowed", "allowed_networks", "check_url",
           "post", "resolve"]
