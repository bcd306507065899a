"""Remove what matches left behind (after a crash or kill -9), found by our labels.

Containers go first (so networks have no endpoints left), then networks, then the host firewall
rules and the loop-mounted log folders.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass

from orchestrator.errors import OrchestratorError
from orchestrator.match.host import Host
from orchestrator.match.runtime import ContainerRuntime, ObjectNotFound

log = logging.getLogger(__name__)


@dataclass(frozen=True, slots=True, kw_only=True)
class CleanupReport:
    containers: tuple[str, ...]
    networks: tuple[str, ...]
    host_objects: int
    errors: tuple[str, ...] = ()


def cleanup(runtime: ContainerRuntime, host: Host, *, match_id: str | None = None
            ) -> CleanupReport:
    """Remove every container and network of ``match_id`` (or of every match)."""
    found = runtime.list_project(match_id=match_id)
    containers: list[str] = []
    networks: list[str] = []
    errors: list[str] = []
    for obj in found:
        if obj.kind != "container":
            continue
        try:
            runtime.remove(obj.id)
            containers.append(obj.name)
        except ObjectNotFound:
            continue
        except OrchestratorError as exc:
            errors.append(str(exc))
    for obj in found:
        if obj.kind != "network":
            continue
        try:
            runtime.remove_network(obj.id)
            networks.append(obj.name)
        except ObjectNotFound:
            continue
        except OrchestratorError as exc:
            errors.append(str(exc))
    host_objects = host.cleanup(match_id=match_id)
    for name in containers + networks:
        log.info("cleanup: removed %s", name)
    return CleanupReport(containers=tuple(containers), networks=tuple(networks),
                         host_objects=host_objects, errors=tuple(errors))


__all__ = ["CleanupReport", "cleanup"]
