"""Host-side controls of a match: firewall, bandwidth and size-capped log folders.

:class:`HostControl` is the real implementation (root on Linux); ``FakeHost`` in
``orchestrator.match.fake`` records calls for unit tests. Each feature can be turned off (the
result then records that it was not applied).
"""

from __future__ import annotations

import logging
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Protocol

from orchestrator import bandwidth
from orchestrator.bandwidth import AppliedShaping, RobotShaping, TrafficCounters
from orchestrator.engine import networks, nodes
from orchestrator.match import logfs
from orchestrator.match.logfs import LogFolder
from orchestrator.match.placement import NodeFirewall
from orchestrator.match.safecopy import CopyReport

log = logging.getLogger(__name__)


class Host(Protocol):
    def isolate_bridge(self, bridge_name: str, *, match_id: str) -> bool: ...

    def remove_isolation(self, *, match_id: str | None) -> int: ...

    def shape(self, pid: int, shaping: RobotShaping) -> AppliedShaping | None: ...

    def shape_node(self, netns: str, shaping: RobotShaping) -> AppliedShaping | None: ...

    def unshape(self, applied: AppliedShaping) -> None: ...

    def node_firewall(self, netns: str | None, firewall: NodeFirewall) -> bool: ...

    def remove_node_firewall(self, netns: str | None) -> None: ...

    def in_netns(self, pid: int, netns: str) -> bool: ...

    def counters(self, applied: AppliedShaping) -> TrafficCounters: ...

    def log_folder(self, *, match_id: str, name: str, cap_bytes: int, fallback: Path
                   ) -> LogFolder: ...

    def collect_logs(self, folder: LogFolder, destination: Path, *,
                     limit_bytes: int | None = None) -> CopyReport: ...

    def release(self, folder: LogFolder) -> None: ...

    def cleanup(self, *, match_id: str | None) -> int: ...


@dataclass(frozen=True, slots=True, kw_only=True)
class HostControl:
    firewall: bool = True
    shaping: bool = True
    capped_logs: bool = True

    @classmethod
    def for_current_user(cls) -> HostControl:
        """Everything on as root; without root (traffic control, iptables and mount need it)
        everything off, with a warning: the match still plays, and results.json records which
        limits were not applied."""
        if os.geteuid() == 0:
            return cls()
        log.warning(
            "not running as root: no bandwidth limits, no host firewall rules and no size cap "
            "on /robocup-logs for this match"
        )
        return cls(firewall=False, shaping=False, capped_logs=False)

    def describe(self) -> dict[str, bool]:
        return {"firewall": self.firewall, "shaping": self.shaping,
                "capped_logs": self.capped_logs}

    def isolate_bridge(self, bridge_name: str, *, match_id: str) -> bool:
        if not self.firewall:
            return False
        if not networks.firewall_available():
            log.warning("iptables not found: host services stay reachable from %s", bridge_name)
            return False
        networks.isolate_bridge(bridge_name, match_id=match_id)
        return True

    def remove_isolation(self, *, match_id: str | None) -> int:
        return networks.remove_isolation(match_id=match_id) if self.firewall else 0

    def shape(self, pid: int, shaping: RobotShaping) -> AppliedShaping | None:
        if not self.shaping:
            return None
        return bandwidth.apply(pid, shaping)

    def shape_node(self, netns: str, shaping: RobotShaping) -> AppliedShaping | None:
        """League placement: the limits on the robot node's interface."""
        if not self.shaping:
            return None
        return bandwidth.apply_netns(netns, shaping, replace=True)

    def unshape(self, applied: AppliedShaping) -> None:
        bandwidth.remove(applied)

    def node_firewall(self, netns: str | None, firewall: NodeFirewall) -> bool:
        """League placement: the robot node's firewall (:mod:`orchestrator.engine.nodes`)."""
        if not self.firewall:
            return False
        nodes.apply(netns, firewall)
        return True

    def remove_node_firewall(self, netns: str | None) -> None:
        if self.firewall:
            nodes.remove(netns)

    def in_netns(self, pid: int, netns: str) -> bool:
        """Whether process ``pid`` has entered the network namespace ``netns`` (a path)."""
        try:
            mine, theirs = os.stat(f"/proc/{pid}/ns/net"), os.stat(netns)
        except OSError:
            return False
        return (mine.st_dev, mine.st_ino) == (theirs.st_dev, theirs.st_ino)

    def counters(self, applied: AppliedShaping) -> TrafficCounters:
        return bandwidth.read_counters(applied)

    def log_folder(self, *, match_id: str, name: str, cap_bytes: int, fallback: Path
                   ) -> LogFolder:
        if not self.capped_logs:
            fallback.mkdir(parents=True, exist_ok=True)
            fallback.chmod(0o777)
            return LogFolder(path=fallback, cap_bytes=None)
        return logfs.create(match_id=match_id, name=name, cap_bytes=cap_bytes,
                            fallback_dir=fallback)

    def collect_logs(self, folder: LogFolder, destination: Path, *,
                     limit_bytes: int | None = None) -> CopyReport:
        return logfs.collect(folder, destination, limit_bytes=limit_bytes)

    def release(self, folder: LogFolder) -> None:
        logfs.release(folder)

    def cleanup(self, *, match_id: str | None) -> int:
        removed = self.remove_isolation(match_id=match_id)
        if self.capped_logs:
            removed += logfs.cleanup(match_id=match_id)
        return removed


__all__ = ["Host", "HostControl"]
