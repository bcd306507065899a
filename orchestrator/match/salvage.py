"""Salvage a match whose orchestrator is gone: stop its containers and save what the teams
produced (each robot's stdout/stderr and ``/robocup-logs``) and the simulator's public files into
the match's output folder, with a ``report.json`` that says the match was interrupted.
"""

from __future__ import annotations

import logging
import os
import re
import shutil
from dataclasses import dataclass, field, replace
from pathlib import Path

from contracts import MatchResults, Salvage, SalvagedRobot, files
from orchestrator.engine import LABEL_ROBOT, LABEL_ROLE, LABEL_TEAM
from orchestrator.errors import OrchestratorError
from orchestrator.match import logfs
from orchestrator.match.layout import ROBOT_CONSOLE_BYTES
from orchestrator.match.ownership import RunRecord
from orchestrator.match.results import Failure, FailureClass, write_report, write_results
from orchestrator.match.safecopy import copy_tree, restrict
from orchestrator.runtime.port import ContainerRuntime, ProjectObject

log = logging.getLogger(__name__)

STOP_TIMEOUT_S = 10.0
PUBLIC_FILES = (
    files.SIM_RESULT, files.REPLAY, files.API_STATS, files.REFEREE_LOG, files.REFEREE_EVENTS,
    files.GAMECONTROLLER_LOG, "bouncing_log.txt",
)  # a salvaged match has no video


@dataclass(slots=True)
class SalvageReport:
    out_dir: str
    robots: dict[str, SalvagedRobot] = field(default_factory=dict)
    public: list[str] = field(default_factory=list)
    errors: list[str] = field(default_factory=list)


def _robot_key(obj: ProjectObject) -> tuple[str, str] | None:
    team, number = obj.labels.get(LABEL_TEAM, ""), obj.labels.get(LABEL_ROBOT, "")
    if team in ("red", "blue") and re.fullmatch(r"[1-9][0-9]?", number):
        return team, number
    return None


def salvage(runtime: ContainerRuntime, record: RunRecord, objects: list[ProjectObject]
            ) -> SalvageReport:
    out = Path(record.out_dir)
    report = SalvageReport(out_dir=str(out))
    containers = [o for o in objects if o.kind == "container"]
    robots = [(o, key) for o in containers if o.labels.get(LABEL_ROLE) == "robot"
              and (key := _robot_key(o)) is not None]
    for obj, (team, number) in robots:
        folder = out / "teams" / team / number
        robot = f"{team}-{number}"
        report.robots.setdefault(robot, SalvagedRobot())
        try:
            runtime.stop(obj.id, timeout_s=STOP_TIMEOUT_S)
            folder.mkdir(parents=True, exist_ok=True, mode=0o700)
            runtime.save_logs(obj.id, stdout=folder / "stdout.log", stderr=folder / "stderr.log",
                              max_bytes=ROBOT_CONSOLE_BYTES // 2)
            report.robots[robot] = replace(report.robots[robot], stdout=True)
        except (OrchestratorError, OSError) as exc:
            report.errors.append(f"{team}-{number}: logs not saved: {exc}")
    for obj in containers:
        if obj.labels.get(LABEL_ROLE) != "simulator":
            continue
        sim_dir = out / "simulator"
        try:
            runtime.stop(obj.id, timeout_s=STOP_TIMEOUT_S)
            runtime.save_logs(obj.id, stdout=sim_dir / "stdout.log", stderr=sim_dir / "stderr.log")
        except (OrchestratorError, OSError) as exc:
            report.errors.append(f"simulator: logs not saved: {exc}")
    public = out / "public"
    for name in PUBLIC_FILES:
        source = out / "simulator" / files.OUT_DIR / name
        if source.is_file() and not source.is_symlink():
            public.mkdir(parents=True, exist_ok=True, mode=0o700)
            shutil.copyfile(source, public / name)
            report.public.append(name)
    base = logfs.state_dir() / "logfs" / logfs.safe_name(record.match_id)
    for team in ("red", "blue"):
        for mount in sorted(base.glob(f"{team}-*")) if base.is_dir() else []:
            number = mount.name.partition("-")[2]
            if not mount.is_dir() or mount.is_symlink() or not number.isdigit():
                continue
            try:  # at most what the capped folder holds; one robot's folder breaks nothing
                size = os.statvfs(mount)
                copied = copy_tree(mount, out / "teams" / team / number / "robocup-logs",
                                   limit_bytes=size.f_blocks * size.f_frsize)
            except Exception as exc:  # noqa: BLE001
                report.errors.append(f"{mount.name}: /robocup-logs not salvaged: {exc}")
                continue
            saved = report.robots.get(mount.name, SalvagedRobot())
            report.robots[mount.name] = replace(saved, log_folder=copied.record())
    cause = (f"the orchestrator (pid {record.pid} on {record.hostname}) was gone; hlvs cleanup "
             "stopped the match and salvaged the teams' logs")
    failure = Failure(failure_class=FailureClass.INTERRUPTED, cause=cause)
    if not (out / files.RESULTS).is_file():
        write_results(out, MatchResults(
            match_id=record.match_id, status="failed", failure=failure,
            salvaged=Salvage(robots=report.robots, public=tuple(report.public),
                             errors=tuple(report.errors)),
        ))
    restrict(out)
    write_report(out, failure)
    log.info("match %s: salvaged into %s (%d robots)", record.match_id, out, len(report.robots))
    return report


__all__ = ["SalvageReport", "salvage"]
