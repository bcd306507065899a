"""The firewall of a robot node in league placement (``iptables`` in the node's network).

A robot shares its node's network with the node's own daemons (``slurmd`` must keep talking to
the controller), so the rules apply to the robot's processes only: robot containers run in the
cgroup :data:`ROBOT_CGROUP` (Docker ``--cgroup-parent``), and the OUTPUT chain sends what a
socket of that cgroup emits to :data:`CHAIN_OUT` (``-m cgroup --path``, cgroup v2), which
accepts the robot's API port, the UDP ports of the mirror and the GameController on the
simulator node and the teammates' nodes, and rejects everything else (the control network, the
opponents' nodes, the internet). :data:`CHAIN_IN` rejects whatever arrives from the opponents'
nodes. The rules are made before the robot starts and removed when the match ends (the
cluster's epilog removes any that a killed match left).
"""

from __future__ import annotations

import logging
import subprocess
from pathlib import Path

from orchestrator.errors import InfrastructureError
from orchestrator.runtime.port import ROBOT_CGROUP, ROBOT_CGROUP_PARENT, NodeFirewall

log = logging.getLogger(__name__)

CHAIN_OUT = "HLVS-ROBOTS"
CHAIN_IN = "HLVS-ROBOTS-IN"
REJECT = ("-j", "REJECT", "--reject-with", "icmp-admin-prohibited")


def cgroup2_root() -> Path:
    """Where the cgroup v2 hierarchy is mounted (``/sys/fs/cgroup`` or, on a hybrid host,
    ``/sys/fs/cgroup/unified``)."""
    for line in Path("/proc/self/mounts").read_text().splitlines():
        fields = line.split()
        if len(fields) > 2 and fields[2] == "cgroup2":
            return Path(fields[1])
    raise InfrastructureError("no cgroup v2 hierarchy is mounted: the robot node firewall "
                              "matches robot processes by their cgroup v2 path")


def ensure_robot_cgroup() -> str:
    """Make the robots' parent cgroup (the firewall rule names it, so it must exist first);
    returns Docker's ``--cgroup-parent`` for robot containers."""
    (cgroup2_root() / ROBOT_CGROUP).mkdir(exist_ok=True)
    return ROBOT_CGROUP_PARENT


def _iptables(netns: str | None, *args: str, check: bool = True) -> bool:
    prefix = ["nsenter", f"--net={netns}"] if netns else []
    try:
        result = subprocess.run([*prefix, "iptables", "-w", *args], capture_output=True,
                                text=True, timeout=30, check=False)
    except (OSError, subprocess.TimeoutExpired) as exc:
        raise InfrastructureError(f"iptables in {netns or 'this network'}: {exc}") from exc
    if check and result.returncode != 0:
        raise InfrastructureError(f"iptables {' '.join(args)} in {netns or 'this network'}: "
                                  f"{result.stderr.strip()}")
    return result.returncode == 0


def apply(netns: str | None, firewall: NodeFirewall) -> None:
    """Close the robot node to everything the robot may not reach (see the module doc)."""
    remove(netns)  # rules of an earlier match on this node that did not end cleanly
    ensure_robot_cgroup()

    def ipt(*args: str) -> None:
        _iptables(netns, *args)

    ipt("-N", CHAIN_OUT)
    ipt("-A", CHAIN_OUT, "-o", "lo", "-j", "ACCEPT")
    ipt("-A", CHAIN_OUT, "-m", "conntrack", "--ctstate", "ESTABLISHED,RELATED", "-j", "ACCEPT")
    ipt("-A", CHAIN_OUT, "-d", firewall.simulator, "-p", "tcp", "--dport",
        str(firewall.api_port), "-j", "ACCEPT")
    for port in firewall.udp_ports:
        ipt("-A", CHAIN_OUT, "-d", firewall.simulator, "-p", "udp", "--dport", str(port),
            "-j", "ACCEPT")
    for mate in firewall.teammates:
        ipt("-A", CHAIN_OUT, "-d", mate, "-j", "ACCEPT")
    ipt("-A", CHAIN_OUT, *REJECT)
    ipt("-N", CHAIN_IN)
    for opponent in firewall.opponents:
        ipt("-A", CHAIN_IN, "-s", opponent, *REJECT)
    ipt("-I", "INPUT", "1", "-j", CHAIN_IN)
    ipt("-I", "OUTPUT", "1", "-m", "cgroup", "--path", ROBOT_CGROUP, "-j", CHAIN_OUT)
    log.info("robot node firewall in %s: simulator %s (tcp %d, udp %s), teammates %s; "
             "opponents %s refused", netns or "this network", firewall.simulator,
             firewall.api_port, ",".join(map(str, firewall.udp_ports)),
             ",".join(firewall.teammates) or "none", ",".join(firewall.opponents) or "none")


def remove(netns: str | None) -> bool:
    """Remove the robot node firewall (idempotent); whether there was one."""
    found = False
    while _iptables(netns, "-D", "OUTPUT", "-m", "cgroup", "--path", ROBOT_CGROUP, "-j",
                    CHAIN_OUT, check=False):
        found = True
    while _iptables(netns, "-D", "INPUT", "-j", CHAIN_IN, check=False):
        found = True
    for chain in (CHAIN_OUT, CHAIN_IN):
        if _iptables(netns, "-F", chain, check=False):
            found = True
            _iptables(netns, "-X", chain, check=False)
    return found


def rules(netns: str | None) -> str:
    """The node's rules as ``iptables -S`` prints them (tests, diagnostics)."""
    prefix = ["nsenter", f"--net={netns}"] if netns else []
    return subprocess.run([*prefix, "iptables", "-w", "-S"], capture_output=True, text=True,
                          timeout=30, check=False).stdout


__all__ = ["CHAIN_IN", "CHAIN_OUT", "apply",
           "ensure_robot_cgroup", "remove", "rules"]
