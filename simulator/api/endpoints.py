"""Which robot listens on which port, and who may connect to it."""

from __future__ import annotations

import ipaddress
import socket
from collections.abc import Sequence
from dataclasses import dataclass

from referee.snapshot import RobotId, TeamColor
from simulator.spec import MatchSpec


@dataclass(frozen=True, slots=True, kw_only=True)
class PlayerEndpoint:
    """One robot API port. ``hosts`` are the team's allowed peers (IPs or host names)."""

    robot: RobotId
    port: int
    hosts: tuple[str, ...]
    team_size: int

    @property
    def allowed_ips(self) -> frozenset[str]:
        return frozenset(h for h in self.hosts if _is_ip(h))

    @property
    def allowed_names(self) -> frozenset[str]:
        return frozenset(h for h in self.hosts if not _is_ip(h))


def _is_ip(text: str) -> bool:
    try:
        ipaddress.ip_address(text)
    except ValueError:
        return False
    return True


def endpoints_from_spec(spec: MatchSpec) -> list[PlayerEndpoint]:
    result: list[PlayerEndpoint] = []
    for team in (spec.red, spec.blue):
        color = TeamColor(team.color)
        for player in team.players:
            result.append(
                PlayerEndpoint(
                    robot=RobotId(color, player.number),
                    port=player.port,
                    hosts=team.hosts,
                    team_size=len(team.players),
                )
            )
    return result


def peer_allowed_by_name(ip: str, names: Sequence[str]) -> bool:
    """HLVS-style name check (may block on DNS: call it off the step thread).

    The peer is allowed when its reverse name (or an alias) is listed, or when a listed name
    resolves to the peer's address.
    """
    wanted = set(names)
    try:
        hostname, aliases, _ = socket.gethostbyaddr(ip)
        if hostname in wanted or wanted.intersection(aliases):
            return True
    except OSError:
        pass  # no reverse name: fall through to forward lookups
    for name in names:
        try:
            infos = socket.getaddrinfo(name, None, proto=socket.IPPROTO_TCP)
        except OSError:
            continue
        if any(info[4][0] == ip for info in infos):
            return True
    return False


def free_ports(count: int) -> list[int]:
    """``count`` distinct TCP ports free on 127.0.0.1 now (benches and tests)."""
    socks = [socket.socket() for _ in range(count)]
    try:
        for s in socks:
            s.bind(("127.0.0.1", 0))
        return [int(s.getsockname()[1]) for s in socks]
    finally:
        for s in socks:
            s.close()
