"""Docker networks of a match and the host firewall rules that go with them.

Docker calls are made through :class:`orchestrator.engine.containers.DockerRuntime` (which
translates errors); the firewall functions run ``iptables`` on the host.

Why a firewall rule: a container on any bridge network, internal or not, reaches services the host
binds to 0.0.0.0 through the bridge's gateway address; that traffic goes through the host's INPUT
chain, which Docker's isolation rules (FORWARD chain) do not cover. :func:`isolate_bridge` adds
``INPUT -i <bridge> -j DROP`` (with a comment naming the match) for each team bridge, so robots
reach nothing on the host; traffic between containers of one bridge is bridged, not routed, and
is unaffected.
"""

from __future__ import annotations

import logging
import shutil
import subprocess

import docker

from orchestrator.errors import InfrastructureError
from orchestrator.runtime.port import NetworkInfo, NetworkRequest, SubnetInUse

log = logging.getLogger(__name__)

COMMENT_PREFIX = "hlvs-runner:"


def create_network(client: docker.DockerClient, request: NetworkRequest) -> NetworkInfo:
    api = client.api
    ipam = docker.types.IPAMConfig(
        pool_configs=[docker.types.IPAMPool(subnet=request.subnet, gateway=request.gateway)]
    )
    try:
        created = api.create_network(
            request.name,
            driver="bridge",
            internal=request.internal,
            ipam=ipam,
            labels=dict(request.labels),
            options={
                "com.docker.network.bridge.name": request.bridge_name,
                "com.docker.network.bridge.enable_icc": "true",
            },
            check_duplicate=True,
        )
    except docker.errors.APIError as exc:
        text = str(exc.explanation or exc)
        if "overlap" in text or "Pool" in text:
            raise SubnetInUse(subnet=request.subnet, reason=text) from exc
        raise
    log.info(
        "network %s created (%s, bridge %s, %s)",
        request.name,
        request.subnet,
        request.bridge_name,
        "internal" if request.internal else "with internet",
    )
    return NetworkInfo(
        id=str(created["Id"]),
        name=request.name,
        subnet=request.subnet,
        gateway=request.gateway,
        bridge_name=request.bridge_name,
    )


def remove_network(client: docker.DockerClient, name: str) -> None:
    client.api.remove_network(name)
    log.info("network %s removed", name)


# host firewall ------------------------------------------------------------------------------

IPTABLES = ("iptables", "ip6tables")  # IPv6 is off in our containers; the rule is kept anyway


def firewall_available() -> bool:
    return shutil.which("iptables") is not None


def _run(tool: str, *args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [tool, "-w", "5", *args], capture_output=True, text=True, check=False, timeout=30
    )


def isolate_bridge(bridge_name: str, *, match_id: str) -> None:
    """Drop everything a container on ``bridge_name`` sends to the host itself."""
    comment = f"{COMMENT_PREFIX}{match_id}"[:250]
    for tool in IPTABLES:
        if shutil.which(tool) is None:
            continue
        result = _run(
            tool, "-I", "INPUT", "1", "-i", bridge_name, "-m", "comment", "--comment", comment,
            "-j", "DROP",
        )
        if result.returncode != 0:
            raise InfrastructureError(
                f"cannot add the host firewall rule ({tool}) for bridge {bridge_name}: "
                f"{result.stderr.strip() or result.stdout.strip()}"
            )
    log.info("host services closed to bridge %s (match %s)", bridge_name, match_id)


def remove_isolation(*, match_id: str | None = None) -> int:
    """Delete our INPUT rules (of one match, or all of them); returns how many were removed."""
    removed = 0
    for tool in IPTABLES:
        if shutil.which(tool) is not None:
            removed += _remove(tool, match_id)
    return removed


def _remove(tool: str, match_id: str | None) -> int:
    listed = _run(tool, "-S", "INPUT")
    if listed.returncode != 0:
        raise InfrastructureError(f"cannot list host firewall rules: {listed.stderr.strip()}")
    removed = 0
    wanted = f"{COMMENT_PREFIX}{match_id}" if match_id is not None else COMMENT_PREFIX
    for line in listed.stdout.splitlines():
        if not line.startswith("-A INPUT") or "--comment" not in line:
            continue
        comment = line.split("--comment", 1)[1].split()[0].strip('"')
        if not comment.startswith(COMMENT_PREFIX) or (match_id is not None and comment != wanted):
            continue
        spec = [part.strip('"') for part in line.split()[2:]]
        result = _run(tool, "-D", "INPUT", *spec)
        if result.returncode == 0:
            removed += 1
        else:
            log.warning("cannot delete firewall rule %r: %s", line, result.stderr.strip())
    return removed


__all__ = [
    "COMMENT_PREFIX",
    "SubnetInUse",
    "create_network",
    "firewall_available",
    "isolate_bridge",
    "remove_isolation",
    "remove_network",
]
