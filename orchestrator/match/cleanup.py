"""Remove what matches left behind (after a crash or kill -9), found by our labels.

Only objects in this runner's records are touched (:mod:`orchestrator.runtime.ledger`: labels
alone prove nothing, a team's image can carry them), and only of matches whose orchestrator is
gone (see :mod:`orchestrator.match.ownership`), or of one match named by the operator (refused
while its orchestrator runs). Before anything is
removed, the teams' logs are salvaged into the match's output folder. Then containers go first
(so networks have no endpoints left), then networks, then the host firewall rules and the
loop-mounted log folders. Objects of a match with no run record are listed, never removed, unless
that match is named.
"""

from __future__ import annotations

import logging
from collections.abc import Callable
from dataclasses import dataclass, field

from orchestrator.engine import LABEL_MATCH
from orchestrator.errors import OrchestratorError
from orchestrator.match import logfs, ownership
from orchestrator.match.host import Host
from orchestrator.match.ownership import LABEL_RUN, MatchRunning, RunRecord
from orchestrator.match.salvage import salvage
from orchestrator.runtime.port import ContainerRuntime, ObjectNotFound, ProjectObject

log = logging.getLogger(__name__)


@dataclass(frozen=True, slots=True, kw_only=True)
class CleanupReport:
    containers: tuple[str, ...]
    networks: tuple[str, ...]
    host_objects: int
    errors: tuple[str, ...] = ()
    salvaged: tuple[str, ...] = ()  # output folders the teams' logs were saved into
    skipped: tuple[str, ...] = ()  # matches left alone, with the reason
    mounts: tuple[str, ...] = ()  # mounted log / scratch folders (listed by a dry run)


@dataclass(slots=True)
class _Totals:
    containers: list[str] = field(default_factory=list)
    networks: list[str] = field(default_factory=list)
    host_objects: int = 0
    errors: list[str] = field(default_factory=list)
    salvaged: list[str] = field(default_factory=list)
    skipped: list[str] = field(default_factory=list)
    mounts: list[str] = field(default_factory=list)

    def report(self) -> CleanupReport:
        return CleanupReport(
            containers=tuple(self.containers), networks=tuple(self.networks),
            host_objects=self.host_objects, errors=tuple(self.errors),
            salvaged=tuple(self.salvaged), skipped=tuple(sorted(set(self.skipped))),
            mounts=tuple(self.mounts),
        )


def cleanup(runtime: ContainerRuntime, host: Host, *, match_id: str | None = None
            ) -> CleanupReport:
    """Clean ``match_id`` (refused while its orchestrator runs), or every match whose
    orchestrator is gone."""

    def clean(one: str, record: RunRecord | None, totals: _Totals) -> None:
        clean_match(runtime, host, match_id=one, record=record, totals=totals)

    return _sweep(runtime, match_id, clean)


def plan_cleanup(runtime: ContainerRuntime, *, match_id: str | None = None) -> CleanupReport:
    """What :func:`cleanup` would do, doing nothing (``hlvs cleanup --dry-run``): the containers
    and networks it would remove, the output folders it would salvage logs into, the matches it
    would leave alone and why, and the mounted log and scratch folders it would unmount.
    """

    def plan(one: str, record: RunRecord | None, totals: _Totals) -> None:
        found = _ours(runtime.list_project(match_id=one), totals)
        mounts = logfs.mounted(match_id=one)
        leftover_logs = (logfs.state_dir() / "logfs" / logfs.safe_name(one)).is_dir()
        if record is not None and (found or leftover_logs):
            totals.salvaged.append(record.out_dir)
        totals.containers += sorted(o.name for o in found if o.kind == "container")
        totals.networks += sorted(o.name for o in found if o.kind == "network")
        totals.host_objects += len(mounts)
        totals.mounts += mounts

    return _sweep(runtime, match_id, plan)


def _sweep(runtime: ContainerRuntime, match_id: str | None,
           each: Callable[[str, RunRecord | None, _Totals], None]) -> CleanupReport:
    """The matches a cleanup handles, each given to ``each`` (which removes what it left, or,
    in a dry run, lists it) with the totals: ``match_id`` (refused while its orchestrator
    runs), or every match whose orchestrator is gone; the matches left alone are listed with
    the reason."""
    totals = _Totals()
    if match_id is not None:
        record = ownership.read(match_id)
        if record is not None and ownership.owner_alive(record):
            raise MatchRunning(record)
        each(match_id, record, totals)
        return totals.report()
    owned: dict[str, RunRecord] = {}
    for record in ownership.records():
        owned[record.match_id] = record
        if ownership.owner_alive(record):
            totals.skipped.append(f"{record.match_id}: its orchestrator (pid {record.pid} on "
                                  f"{record.hostname}) is running")
            continue
        each(record.match_id, record, totals)
    for obj in runtime.list_project():
        other = obj.labels.get(LABEL_MATCH)
        if other and other not in owned:
            totals.skipped.append(f"{other}: no run record (name it: hlvs cleanup --match "
                                  f"{other})")
    return totals.report()


def clean_match(runtime: ContainerRuntime, host: Host, *, match_id: str,
                record: RunRecord | None, keep_run: str | None = None,
                totals: _Totals | None = None) -> CleanupReport:
    """Salvage (when the run record names an output folder) and remove one match's objects;
    objects labelled with run ``keep_run`` (the caller's own) are kept."""
    totals = totals if totals is not None else _Totals()
    found = _ours(runtime.list_project(match_id=match_id), totals)
    found = [o for o in found if keep_run is None or o.labels.get(LABEL_RUN) != keep_run]
    leftover_logs = (logfs.state_dir() / "logfs" / logfs.safe_name(match_id)).is_dir()
    if record is not None and (found or leftover_logs):
        try:
            salvaged = salvage(runtime, record, found)
            totals.salvaged.append(salvaged.out_dir)
            totals.errors.extend(salvaged.errors)
        except (OrchestratorError, OSError) as exc:
            totals.errors.append(f"{match_id}: salvage failed: {exc}")
    _remove(runtime, found, totals)
    try:
        totals.host_objects += host.cleanup(match_id=match_id)
    except OrchestratorError as exc:
        totals.errors.append(f"{match_id}: {exc}")
    if record is not None:
        ownership.forget(record)
    return totals.report()


def _ours(found: list[ProjectObject], totals: _Totals) -> list[ProjectObject]:
    """The objects this runner created (in its ledger); the others carry our labels without
    being ours (an image with the labels baked in) and are listed, never touched."""
    for obj in found:
        if not obj.created:
            totals.skipped.append(f"{obj.kind} {obj.name}: carries the labels of match "
                                  f"{obj.labels.get(LABEL_MATCH, '?')} but this runner did not "
                                  "create it (not in its records); left alone")
    return [o for o in found if o.created]


def _remove(runtime: ContainerRuntime, found: list[ProjectObject], totals: _Totals) -> None:
    for kind in ("container", "network"):
        for obj in found:
            if obj.kind != kind:
                continue
            try:
                if kind == "container":
                    runtime.remove(obj.id)
                    totals.containers.append(obj.name)
                else:
                    runtime.remove_network(obj.id)
                    totals.networks.append(obj.name)
                log.info("cleanup: removed %s", obj.name)
            except ObjectNotFound:
                continue
            except OrchestratorError as exc:
                totals.errors.append(str(exc))


__all__ = ["CleanupReport", "clean_match", "cleanup", "plan_cleanup"]
