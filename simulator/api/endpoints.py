"""Which robot listens on which port, and who may connect to it."""

from __future__ import annotations

import ipaddress
import socket
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

from contracts import MatchSpec, RobotId, TeamColor


@dataclass(frozen=True, slots=True, kw_only=True)
class PlayerEndpoint:
    """One robot API port. ``hosts`` are the team's allowed peers (IPs or host names).

    ``others`` maps the addresses of the match's other robots to their keys (``red-2``): when
    the robots' addresses are known, a robot's port refuses every other robot's address, so a
    robot can only speak as itself.
    """

    robot: RobotId
    port: int
    hosts: tuple[str, ...]
    team_size: int
    others: Mapping[str, str] = field(default_factory=dict)

    @property
    def key(self) -> str:
        return f"{self.robot.team.value}-{self.robot.number}"

    @property
    def allowed_ips(self) -> frozenset[str]:
        return frozenset(h for h in self.hosts if _is_ip(h) and h not in self.others)

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
    addresses = {
        f"{team.color}-{n}": address
        for team in (spec.red, spec.blue)
        for n, address in enumerate(team.robot_addresses, start=1)
        if address
    }
    result: list[PlayerEndpoint] = []
    for team in (spec.red, spec.blue):
        color = TeamColor(team.color)
        for player in team.players:
            key = f"{team.color}-{player.number}"
            own = addresses.get(key)
            others = {a: k for k, a in addresses.items() if k != key and a != own}
            result.append(
                PlayerEndpoint(
                    robot=RobotId(color, player.number),
                    port=player.port,
                    hosts=team.hosts,
                    team_size=len(team.players),
                    others=others,
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
