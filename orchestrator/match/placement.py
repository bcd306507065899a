"""League placement: the simulator on a node of its own and each robot on a node of its own.

As the virtual league ran its matches (one simulator VM, one VM per robot), a robot uses its
node's network the way ``--network host`` does on a robot VM: the ``ROBOCUP_*`` variables carry
the nodes' real addresses (:class:`NodeAddresses` stands in for the dense placement's team
subnet in :func:`orchestrator.match.layout.robot_environment`), the simulator's ports, the
mirror and the GameController are reached on the simulator node's address, and each robot node
gets a firewall (:class:`NodeFirewall`: only the simulator's ports and the teammates' nodes,
never the opponents' nodes nor the control network) and its bandwidth limits on its interface.

Where nodes share one Docker engine (the one-machine cluster of ``hlvs pool up``), each node is
a network namespace (``netns`` template, e.g. ``/run/netns/hlvs-{node}``): a small holder
container joins it and the robot container shares the holder's network, which is then the
node's. Pure data and parsing; no I/O.
"""

from __future__ import annotations

import ipaddress
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

from orchestrator.errors import ConfigError, Problem
from orchestrator.runtime.port import ROBOT_CGROUP, ROBOT_CGROUP_PARENT, NodeFirewall

NODES_OPTION = "--league-nodes"
NETNS_OPTION = "--node-netns"


@dataclass(frozen=True, slots=True, kw_only=True)
class Node:
    name: str
    address: str


@dataclass(frozen=True, slots=True, kw_only=True)
class LeaguePlacement:
    simulator: Node
    robots: Mapping[str, Node]  # robot key (red-1...) -> its node
    netns: str | None = None  # "/run/netns/hlvs-{node}": the node's network namespace

    def netns_of(self, node: Node) -> str | None:
        return None if self.netns is None else self.netns.format(node=node.name)

    def addresses(self, color: str, numbers: Sequence[int]) -> NodeAddresses:
        return NodeAddresses(
            simulator=self.simulator.address,
            robots={n: self.robots[f"{color}-{n}"].address for n in numbers},
        )

    def to_json(self) -> dict[str, object]:
        return {"simulator": {"name": self.simulator.name, "address": self.simulator.address},
                "robots": {k: {"name": n.name, "address": n.address}
                           for k, n in self.robots.items()},
                "netns": self.netns}


@dataclass(frozen=True, slots=True, kw_only=True)
class NodeAddresses:
    """The simulator node's address and the address of the node of each robot of one team (the
    two members :func:`orchestrator.match.layout.robot_environment` reads)."""

    simulator: str
    robots: Mapping[int, str]

    def robot(self, number: int) -> str:
        return self.robots[number]


def parse_nodes(text: str, robot_keys: Sequence[str], *, netns: str | None = None
                ) -> LeaguePlacement:
    """``NAME=ADDRESS,...``: the simulator's node first, then one node per robot in
    ``robot_keys`` order (red 1..n, then blue 1..n); every node different."""
    where = NODES_OPTION

    def bad(message: str, expected: str) -> ConfigError:
        return ConfigError([Problem(file="command line", pointer=where, message=message,
                                    expected=expected)])

    items = [item.strip() for item in text.split(",") if item.strip()]
    nodes: list[Node] = []
    for item in items:
        name, sep, address = item.partition("=")
        try:
            ipaddress.IPv4Address(address)
        except ValueError:
            raise bad(f"{item!r} is not NAME=ADDRESS", "a node name, '=', its IPv4 address"
                      ) from None
        if not sep or not name:
            raise bad(f"{item!r} is not NAME=ADDRESS", "a node name, '=', its IPv4 address")
        nodes.append(Node(name=name, address=address))
    if len(nodes) != len(robot_keys) + 1:
        raise bad(f"{len(nodes)} nodes for {len(robot_keys)} robots",
                  f"{len(robot_keys) + 1} nodes: the simulator's, then one per robot "
                  f"({', '.join(robot_keys)})")
    names = [n.name for n in nodes]
    addresses = [n.address for n in nodes]
    if len(set(names)) != len(names) or len(set(addresses)) != len(addresses):
        raise bad(f"a node is named twice in {text!r}", "a node of its own for the simulator "
                  "and for every robot")
    if netns is not None and "{node}" not in netns:
        raise ConfigError([Problem(file="command line", pointer=NETNS_OPTION,
                                   message=f"{netns!r} does not name the node",
                                   expected="a path with {node}, e.g. /run/netns/hlvs-{node}")])
    return LeaguePlacement(simulator=nodes[0], robots=dict(zip(robot_keys, nodes[1:],
                                                               strict=True)), netns=netns)


def firewall_for(placement: LeaguePlacement, *, color: str, number: int, api_port: int,
                 udp_ports: tuple[int, ...]) -> NodeFirewall:
    mine = placement.robots[f"{color}-{number}"]
    teammates = tuple(n.address for k, n in placement.robots.items()
                      if k.startswith(f"{color}-") and n != mine)
    opponents = tuple(n.address for k, n in placement.robots.items()
                      if not k.startswith(f"{color}-"))
    return NodeFirewall(simulator=placement.simulator.address, api_port=api_port,
                        udp_ports=udp_ports, teammates=teammates, opponents=opponents)


__all__ = ["LeaguePlacement", "NETNS_OPTION", "NODES_OPTION", "ROBOT_CGROUP",
           "ROBOT_CGROUP_PARENT", "Node", "NodeAddresses",
           "NodeFirewall", "firewall_for", "parse_nodes"]
