"""What a match leaves behind: ``results.json`` and, written last, ``report.json``.

``report.json`` is ``{"status": "success"}`` or ``{"status": "failed", "failure_class": ...,
"cause": ...}``; a reader that finds it knows every other file of the match folder is complete.

Failure classes:

- ``infrastructure``: the engine, a network, the host firewall or a mount failed us;
- ``image_pull``: no robot of either team has a usable image;
- ``team_startup``: the containers of a team's robots could not be created or started;
- ``team_crash``: reserved for a team whose robots break the match (a robot that exits or is
  OOM-killed mid-game does *not* fail the match; it is recorded per robot);
- ``simulator``: the simulator container exited without FINISHED, or its telemetry was silent;
- ``referee``: the simulator ran to its end but the game did not reach FINISHED;
- ``interrupted``: the orchestrator was asked to stop (SIGINT / SIGTERM).
"""

from __future__ import annotations

import enum
import json
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from contracts import files
from contracts.codec import to_data
from contracts.sim_result import SimResult


class FailureClass(enum.Enum):
    INFRASTRUCTURE = "infrastructure"
    IMAGE_PULL = "image_pull"
    TEAM_STARTUP = "team_startup"
    TEAM_CRASH = "team_crash"
    SIMULATOR = "simulator"
    REFEREE = "referee"
    INTERRUPTED = "interrupted"


@dataclass(frozen=True, slots=True, kw_only=True)
class Failure:
    failure_class: FailureClass
    cause: str


@dataclass(slots=True, kw_only=True)
class RobotRecord:
    """Everything recorded about one robot during the match (filled in as the match runs)."""

    key: str
    color: str
    number: int
    image: str | None
    digest: str | None = None
    image_error: str | None = None
    container: str | None = None  # container name when one was started
    startup_error: str | None = None
    exit_code: int | None = None
    oom_killed: bool = False
    restarts: int = 0
    exited_during_game: bool = False
    cpu_peak_percent: float = 0.0
    memory_peak_bytes: int = 0
    sent_bytes: int | None = None
    received_bytes: int | None = None
    limits: dict[str, Any] = field(default_factory=dict)
    log_folder: dict[str, Any] | None = None  # what collection copied and skipped

    def to_json(self, api: dict[str, Any] | None) -> dict[str, Any]:
        return {
            "image": self.image,
            "digest": self.digest,
            "image_error": self.image_error,
            "container": self.container,
            "startup_error": self.startup_error,
            "exit_code": self.exit_code,
            "oom_killed": self.oom_killed,
            "restarts": self.restarts,
            "exited_during_game": self.exited_during_game,
            "cpu_peak_percent": round(self.cpu_peak_percent, 1),
            "memory_peak_bytes": self.memory_peak_bytes,
            "sent_bytes": self.sent_bytes,
            "received_bytes": self.received_bytes,
            "limits": self.limits,
            "api": api,
            "log_folder": self.log_folder,
            "spoofing_attempts": 0,  # messages sent as another robot (set from the simulator)
        }


def _write_json(path: Path, data: dict[str, Any]) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_suffix(path.suffix + ".tmp")
    tmp.write_text(json.dumps(data, indent=2, sort_keys=True) + "\n", encoding="utf-8")
    tmp.chmod(0o600)
    os.replace(tmp, path)


def build_results(
    *,
    match_id: str,
    seed: int,
    sim_result: SimResult | None,
    robots: list[RobotRecord],
    forfeit: dict[str, Any] | None,
    limits: dict[str, Any],
    versions: dict[str, Any],
    timings_s: dict[str, float],
    failure: Failure | None,
) -> dict[str, Any]:
    sim = sim_result
    api_stats: dict[str, Any] = sim.robots if sim is not None else {}
    score: Any = sim.score if sim is not None else None
    winner: Any = sim.winner if sim is not None else None
    if forfeit is not None:
        score = forfeit.get("score", score)
        winner = forfeit.get("winner")
    spoofing = sim.spoofing if sim is not None else None
    robot_json = {r.key: r.to_json(api_stats.get(r.key)) for r in robots}
    for attempt in (spoofing or {}).get("attempts") or []:
        sender = robot_json.get(str(attempt.get("sender_robot")))
        if sender is not None:
            sender["spoofing_attempts"] += int(attempt.get("count") or 0)
    return {
        "match_id": match_id,
        "seed": seed,
        "warnings": team_warnings(robots, api_stats) if sim_result is not None else [],
        "status": "failed" if failure else "success",
        "failure": None
        if failure is None
        else {"class": failure.failure_class.value, "cause": failure.cause},
        "forfeit": forfeit,
        "final_state": sim.state if sim is not None else None,
        "score": score,
        "winner": winner,
        "events_summary": sim.events_summary if sim is not None else {},
        # how much football was played (contracts.sim_result.PlayRecord), None when not counted
        "play": to_data(sim.play) if sim is not None and sim.play is not None else None,
        "sim_time_ms": sim.sim_time_ms if sim is not None else None,
        "real_time_factor": sim.real_time_factor if sim is not None else None,
        "robots": robot_json,
        "spoofing": spoofing,
        "limits": limits,
        "versions": {**versions, "simulator": sim.versions if sim is not None else None},
        "timings_s": timings_s,
    }


def team_warnings(robots: list[RobotRecord], api_stats: dict[str, Any]) -> list[str]:
    """What a score alone hides: a team whose started robots all exited during the game, or
    none of which ever connected to the simulator."""
    warnings = []
    for color in ("red", "blue"):
        started = [r for r in robots if r.color == color and r.container is not None]
        if not started:
            continue
        if all(r.exited_during_game for r in started):
            warnings.append(f"every robot of {color} exited during the game ("
                            + ", ".join(f"{r.key}: exit code {r.exit_code}" for r in started)
                            + ")")
        if not any((api_stats.get(r.key) or {}).get("connects") for r in started):
            warnings.append(f"no robot of {color} ever connected to the simulator")
    return warnings


def write_results(out_dir: Path, results: dict[str, Any]) -> Path:
    path = out_dir / files.RESULTS
    _write_json(path, results)
    return path


def write_report(out_dir: Path, failure: Failure | None) -> Path:
    """Written last: its presence means the match folder is complete."""
    report: dict[str, Any] = {"status": "success"}
    if failure is not None:
        report = {
            "status": "failed",
            "failure_class": failure.failure_class.value,
            "cause": failure.cause,
        }
    path = out_dir / files.REPORT
    _write_json(path, report)
    return path


__all__ = [
    "Failure",
    "FailureClass",
    "RobotRecord",
    "build_results",
    "team_warnings",
    "write_report",
    "write_results",
]
