"""Which addresses a connection a team chose may reach: public unicast addresses, plus the
networks an operator allows.

The submission service applies these rules to everything it sends to an address a team named:
its webhook (``service.outbound``) and its log target (an SFTP ``hostname``, an S3
``endpoint_url``). Loopback, private, link-local (cloud metadata at 169.254.169.254), shared,
multicast and reserved addresses are refused. A name is resolved right before the connection,
every address it resolves to must be allowed, and the connection goes to the address that was
checked (:func:`resolve` returns it), so a name that points elsewhere a moment later (DNS
rebinding) reaches nothing new. The operator's own deliveries (``hlvs match``, ``hlvs logs
deliver``) apply no rules: their targets are the operator's.
"""

from __future__ import annotations

import ipaddress
import socket
from collections.abc import Iterable

IPAddress = ipaddress.IPv4Address | ipaddress.IPv6Address
IPNetwork = ipaddress.IPv4Network | ipaddress.IPv6Network

__all__ = [
    "AddressRefused",
    "IPAddress",
    "IPNetwork",
    "address_allowed",
    "literal_problem",
    "networks",
    "refusal",
    "resolve",
]


class AddressRefused(ValueError):
    """The address is not one a team's connection may reach."""


def networks(text: str) -> tuple[IPNetwork, ...]:
    """Comma-separated networks (``10.20.0.0/16, 127.0.0.1``); ValueError for one that is
    not a network."""
    return tuple(ipaddress.ip_network(part.strip(), strict=False)
                 for part in text.split(",") if part.strip())


def address_allowed(address: IPAddress, allowed: Iterable[IPNetwork]) -> bool:
    """A public unicast address, or one in a network the operator allows."""
    if isinstance(address, ipaddress.IPv6Address) and address.ipv4_mapped is not None:
        address = address.ipv4_mapped
    if any(address.version == n.version and address in n for n in allowed):
        return True
    return address.is_global and not address.is_multicast


def refusal(host: str, address: IPAddress, setting: str) -> str:
    return (f"{host} is {address}, not a public address (the league's own networks are not "
            f"reachable; an operator may allow a network with {setting})")


def literal_problem(host: str, allowed: tuple[IPNetwork, ...], setting: str) -> str | None:
    """What is wrong with ``host`` as written, before any look-up: an address literal that is
    not allowed, or ``localhost``; None for a name (checked again at every connection)."""
    host = host.strip().strip("[]").lower().rstrip(".")
    try:
        address: IPAddress | None = ipaddress.ip_address(host.split("%")[0])
    except ValueError:
        address = None
    if address is not None and not address_allowed(address, allowed):
        return refusal(host, address, setting)
    if address is None and (host == "localhost" or host.endswith(".localhost")):
        return f"{host} is this host, not a public address"
    return None


def resolve(host: str, port: int, allowed: tuple[IPNetwork, ...], setting: str) -> IPAddress:
    """The address to connect to for ``host``; :class:`AddressRefused` when any address the
    name resolves to is not allowed (or it resolves to none)."""
    try:
        infos = socket.getaddrinfo(host, port, type=socket.SOCK_STREAM)
    except (OSError, UnicodeError) as exc:
        raise AddressRefused(f"{host} does not resolve: {exc}") from None
    addresses: list[IPAddress] = []
    for info in infos:
        address = ipaddress.ip_address(str(info[4][0]).split("%")[0])
        if address not in addresses:
            addresses.append(address)
    if not addresses:
        raise AddressRefused(f"{host} resolves to no address")
    for address in addresses:
        if not address_allowed(address, allowed):
            raise AddressRefused(refusal(host, address, setting))
    return addresses[0]
