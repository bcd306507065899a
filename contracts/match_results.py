"""What a match leaves behind: ``results.json`` and, written last, ``report.json``.

Written by the orchestrator (``orchestrator.match.collection``, or ``orchestrator.match.salvage``
for a match whose orchestrator died); read by the scheduler, the submission service, the match
commands and the benchmarks, all through these types. ``report.json``
(:class:`MatchReport`) is ``{"status": "success"}`` or ``{"status": "failed", "failure_class":
..., "cause": ...}``; a reader that finds it knows every other file of the match folder is
complete.

Failure classes (:class:`FailureClass`):

- ``infrastructure``: the engine, a network, the host firewall or a mount failed us;
- ``image_pull``: no robot of either team has a usable image;
- ``team_startup``: the containers of a team's robots could not be created or started;
- ``team_crash``: reserved for a team whose robots break the match (a robot that exits or is
  OOM-killed mid-game does *not* fail the match; it is recorded per robot);
- ``simulator``: the simulator container exited without FINISHED, or its telemetry was silent;
- ``referee``: the simulator ran to its end but the game did not reach FINISHED;
- ``interrupted``: the orchestrator was asked to stop (SIGINT / SIGTERM);
- ``not_played``: the game reached FINISHED but no football was played (no half reached PLAYING,
  or less than the minimum of play of :mod:`contracts.timing`) for a cause of the league: its
  timing, the referee or the simulator;
- ``team_absent``: the same, because no robot of a team ever connected; ``team`` names it.

A failure that one team caused names it in ``team`` (``report.json`` too); a failure without a
team is the league's or the engine's, and is never charged to a team.

Both documents carry a ``version``; a file written before it had one reads as version 1.
"""

from __future__ import annotations

import enum
from dataclasses import dataclass, field
from typing import Any, ClassVar, Literal

from contracts.codec import Versioned, json_key, omitted_when_none
from contracts.jsontypes import JSONObject
from contracts.match_spec import Color
from contracts.sim_result import PlayRecord, RobotApiStats, SpoofingRecord

Status = Literal["success", "failed"]
Scalar = int | float | bool | str | None


class FailureClass(enum.Enum):
    INFRASTRUCTURE = "infrastructure"
    IMAGE_PULL = "image_pull"
    TEAM_STARTUP = "team_startup"
    TEAM_CRASH = "team_crash"
    SIMULATOR = "simulator"
    REFEREE = "referee"
    INTERRUPTED = "interrupted"
    NOT_PLAYED = "not_played"
    TEAM_ABSENT = "team_absent"


@dataclass(frozen=True, slots=True, kw_only=True)
class Failure:
    """Why a match failed (``failure`` of ``results.json``: ``{"class": ..., "cause": ...}``)."""

    failure_class: FailureClass = field(metadata=json_key("class"))
    cause: str
    team: Color | None = field(default=None, metadata=omitted_when_none())  # who caused it


@dataclass(frozen=True, slots=True, kw_only=True)
class Forfeit:
    """A team without any usable image forfeits (the match is not played)."""

    team: Color
    winner: Color
    reason: str
    score: dict[str, int]


@dataclass(frozen=True, slots=True, kw_only=True)
class LogFolderCopy:
    """What was copied from a robot's ``/robocup-logs`` (regular files and folders only)."""

    files: int = 0
    bytes: int = 0
    skipped: tuple[dict[str, str], ...] = ()  # {"path", "kind"}, the first ones only
    skipped_count: int = 0
    stopped: str | None = field(default=None, metadata=omitted_when_none())  # at the size limit


@dataclass(frozen=True, slots=True, kw_only=True)
class RobotResult:
    """One robot's entry in ``robots`` of ``results.json``."""

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
    limits: dict[str, Scalar] = field(default_factory=dict)  # empty when never started
    api: RobotApiStats | None = None  # the simulator's robot API statistics (sim_result)
    log_folder: LogFolderCopy | None = None
    spoofing_attempts: int = 0  # messages sent as another robot (from the simulator)


@dataclass(frozen=True, slots=True, kw_only=True)
class MatchLimits:
    """The limits the match was played under (``limits`` of ``results.json``)."""

    cpus: float
    memory_gb: float
    pids: int
    log_folder_gb: float
    team_api_mb_s: float
    team_comm_mb_s: float
    grace_period_s: float
    allow_internet: bool
    host_controls: dict[str, bool] | None  # which host controls (firewall, shaping) worked


@dataclass(frozen=True, slots=True, kw_only=True)
class NeededAvailable:
    needed: float
    available: float


@dataclass(frozen=True, slots=True, kw_only=True)
class AdmissionRecord:
    """Whether the match fits the host (``admission`` of ``results.json``): an official match
    that does not fit is refused, any other plays with ``warning``."""

    official: bool
    fits: bool
    host: str
    robots: int
    cpus: NeededAvailable
    memory_gb: NeededAvailable
    simulator_cpu_shares: int
    warning: str | None


@dataclass(frozen=True, slots=True, kw_only=True)
class SalvagedRobot:
    stdout: bool | None = field(default=None, metadata=omitted_when_none())  # True: saved
    log_folder: LogFolderCopy | None = field(default=None, metadata=omitted_when_none())


@dataclass(frozen=True, slots=True, kw_only=True)
class Salvage:
    """What ``hlvs cleanup`` saved of a match whose orchestrator was gone."""

    robots: dict[str, SalvagedRobot] = field(default_factory=dict)
    public: tuple[str, ...] = ()
    errors: tuple[str, ...] = ()


SALVAGED_KEYS = ("version", "match_id", "status", "failure", "salvaged")
"""The only keys of a salvaged match's ``results.json`` (nothing else is known of it)."""


@dataclass(frozen=True, slots=True, kw_only=True)
class MatchResults(Versioned):
    """``results.json``. A played (or forfeited, or failed) match fills every field; a match
    salvaged by ``hlvs cleanup`` has only :data:`SALVAGED_KEYS`."""

    VERSION: ClassVar[int] = 1
    KIND: ClassVar[str] = "match results"
    FILE_MODE: ClassVar[int | None] = 0o600  # the teams' data is theirs: owner-only

    match_id: str
    status: Status
    failure: Failure | None
    seed: int | None = None
    warnings: tuple[str, ...] = ()
    forfeit: Forfeit | None = None
    final_state: str | None = None  # the simulator's GameController state at its end
    score: dict[str, int] | None = None  # the match's goals (halves and extra time)
    winner: str | None = None  # "red" | "blue" | "draw"
    # goals of each colour in the penalty shoot-out (the GameController counts them in its
    # score; here they are kept apart from the match's): present only after a shoot-out
    shootout: dict[str, int] | None = field(default=None, metadata=omitted_when_none())
    events_summary: dict[str, int] = field(default_factory=dict)
    play: PlayRecord | None = None  # how much football was played, None when not counted
    sim_time_ms: int | None = None
    real_time_factor: float | None = None
    robots: dict[str, RobotResult] = field(default_factory=dict)
    spoofing: SpoofingRecord | None = None  # from the simulator (sim_result)
    limits: MatchLimits | None = None
    versions: dict[str, str | dict[str, str] | None] = field(default_factory=dict)
    timings_s: dict[str, float] = field(default_factory=dict)  # per match state
    bringup_s: float | None = None  # start of STARTING -> every robot connected
    admission: AdmissionRecord | None = None  # orchestrator.match.admission verdict
    salvaged: Salvage | None = None
    version: int = VERSION

    def __post_init__(self) -> None:
        if self.salvaged is None and (self.seed is None or self.limits is None):
            raise ValueError("seed and limits are required unless the match was salvaged")
        if (self.status == "success") != (self.failure is None):
            raise ValueError(f"status {self.status!r} disagrees with failure {self.failure}")

    def to_dict(self) -> JSONObject:
        data = Versioned.to_dict(self)
        if self.salvaged is None:
            del data["salvaged"]
            return data
        return {key: data[key] for key in SALVAGED_KEYS}


    @property
    def ok(self) -> bool:
        return self.failure is None

    def team_score(self, color: str) -> int | None:
        return None if self.score is None else self.score.get(color)


@dataclass(frozen=True, slots=True, kw_only=True)
class MatchReport(Versioned):
    """``report.json``, written last: the match folder is complete."""

    VERSION: ClassVar[int] = 1
    KIND: ClassVar[str] = "match report"
    FILE_MODE: ClassVar[int | None] = 0o600

    status: Status
    failure_class: FailureClass | None = None
    cause: str | None = None
    # what of the teams' logs was not kept (``{"robot", "what", "reason"}``: a log folder or
    # console output cut at its size limit); the key is present only when something was cut
    logs_cut: tuple[dict[str, str], ...] = ()
    team: Color | None = field(default=None, metadata=omitted_when_none())
    version: int = VERSION

    def __post_init__(self) -> None:
        if (self.status == "success") != (self.failure_class is None):
            raise ValueError(f"status {self.status!r} disagrees with failure_class "
                             f"{self.failure_class}")

    @classmethod
    def of(cls, failure: Failure | None, logs_cut: tuple[dict[str, str], ...] = ()
           ) -> MatchReport:
        if failure is None:
            return cls(status="success", logs_cut=logs_cut)
        return cls(status="failed", failure_class=failure.failure_class, cause=failure.cause,
                   team=failure.team, logs_cut=logs_cut)

    @property
    def failure(self) -> Failure | None:
        if self.failure_class is None:
            return None
        return Failure(failure_class=self.failure_class, cause=self.cause or "", team=self.team)

    def to_dict(self) -> dict[str, Any]:
        """Exactly ``{"status": "success"}`` or ``{"status": "failed", "failure_class": ...,
        "cause": ...}`` (and ``"team"`` when a team caused it), as teams' scripts compare it:
        the version (1) stays implicit until a second one exists. ``logs_cut`` is added only when
        a team's logs were cut."""
        data = Versioned.to_dict(self)
        del data["version"]
        if self.failure_class is None:
            del data["failure_class"], data["cause"]
        if not self.logs_cut:
            del data["logs_cut"]
        return data



__all__ = [
    "SALVAGED_KEYS",
    "AdmissionRecord",
    "Color",
    "Failure",
    "FailureClass",
    "Forfeit",
    "LogFolderCopy",
    "MatchLimits",
    "MatchReport",
    "MatchResults",
    "NeededAvailable",
    "RobotResult",
    "Scalar",
    "Salvage",
    "SalvagedRobot",
]
