"""Validated configuration: frozen dataclasses built from game.json and team_config.json.

Everything here is produced by :mod:`orchestrator.config.loader` after JSON Schema validation and
the cross-file rules; other packages trust these values. Units are in the names (``_s``, ``_gb``,
``_mb_s``, ``_m``, ``_rad``). Poses are kept as the team wrote them: as if the team played on the
left half (x < 0); whoever places robots mirrors them for the team on the right. The shared
vocabulary (colours, field class, game type, stepping, starting poses) is ``contracts``'; the
files keep their spelling (``"class": "KID"`` is :attr:`FieldClass.KID`).
"""

from __future__ import annotations

import shlex
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Literal

from contracts import (
    MIN_PLAYING_S,
    OFFICIAL,
    REMOVAL_PENALTY_S,
    Color,
    FieldClass,
    StartingPose,
    SteppingMode,
)
from contracts import GameTypeName as GameType
from orchestrator.errors import Problem

SideChoice = Literal["red", "blue", "random"]
SensorMode = Literal["league", "ideal"]

COLORS: tuple[Color, Color] = ("red", "blue")
MAX_PLAYERS: dict[FieldClass, int] = {FieldClass.KID: 4, FieldClass.ADULT: 3}
DEFAULT_MODEL: dict[FieldClass, str] = {FieldClass.KID: "kid-default",
                                        FieldClass.ADULT: "adult-default"}
DISPLAY_NAME_CHARS = 12


@dataclass(frozen=True, slots=True, kw_only=True)
class Limits:
    """Resource limits per robot container and per team (league specification defaults)."""

    cpus: float = 4.0
    memory_gb: float = 16.0
    pids: int = 1024
    log_folder_gb: float = 10.0  # per robot /robocup-logs
    scratch_gb: float = 10.0  # per robot writable scratch (/tmp, /var/tmp, /root); root fs is ro
    image_gb: float = 10.0  # one robot image
    team_images_gb: float = 40.0  # all images of one team
    team_api_mb_s: float = 350.0  # robot API traffic of one team, split evenly per robot
    team_comm_mb_s: float = 1.0  # total traffic between the robots of one team
    robot_runtime: str = ""  # the engine's OCI runtime for robots ("runsc": gVisor); "": default


@dataclass(frozen=True, slots=True, kw_only=True)
class Timing:
    """Game timing. Durations of play are simulated seconds; waits and grace are wall seconds."""

    half_duration_s: float = OFFICIAL.half_duration_s
    overtime_half_duration_s: float = 300.0
    ready_duration_s: float = OFFICIAL.ready_duration_s
    # wall time between robot start and first READY
    wait_before_first_ready_s: float = OFFICIAL.wait_before_first_ready_s
    half_time_break_s: float = OFFICIAL.half_time_break_s  # wall time
    grace_period_s: float = OFFICIAL.grace_period_s  # wall time given to robots to stop
    removal_penalty_s: float = REMOVAL_PENALTY_S
    max_duration_s: float | None = None  # HLVS max_duration: stop the game after this wall time
    minimum_play_s: float = MIN_PLAYING_S  # simulated s of PLAYING per half (0: not meant to play)


@dataclass(frozen=True, slots=True, kw_only=True)
class TeamRef:
    """One side of game.json (``red`` or ``blue``)."""

    color: Color
    team_id: int  # GameController team number
    config: Path  # team_config.json, resolved against the game.json folder
    hosts: tuple[str, ...]  # allowed on its API ports outside hlvs match (schema: game.json)
    ports: tuple[int, ...]  # robot API port of player n = ports[n - 1]
    credentials: Path | None = None  # log delivery target of this team (credentials.json)

    def port(self, number: int) -> int:
        return self.ports[number - 1]


@dataclass(frozen=True, slots=True, kw_only=True)
class GameConfig:
    """game.json: the HLVS fields and our optional additions, every default resolved."""

    source: Path
    match_id: str
    seed: int
    game_type: GameType
    field_class: FieldClass  # "class" of game.json ("KID" or "ADULT")
    host: str
    maximum_real_time_factor: float  # <= 0: as fast as possible
    red: TeamRef
    blue: TeamRef
    side_left: SideChoice = "random"
    kickoff: SideChoice = "random"
    press_a_key_to_terminate: bool = False
    use_bouncing_server: bool = False
    record_simulation: str | None = None  # path ending in .html or .mp4, as written
    game_controller_extra_args: tuple[str, ...] = ()
    texture_seed: int | None = None
    sensors: SensorMode = "league"
    camera_motion_blur: bool = False
    supervisor: str | None = None
    stepping: SteppingMode = "async"
    physics_dt_s: float = 0.002
    lockstep_deadline_ms: float = 50.0
    lockstep_time_bank_ms: float = 5000.0
    limits: Limits = field(default_factory=Limits)
    timing: Timing = field(default_factory=Timing)
    allow_internet: bool = False
    official: bool = False  # refused when it does not fit the host (see match.admission)
    # team images only from a registry, with the team's login (default: as ``official``)
    registry_images: bool = False
    gpu: str = "auto"  # auto | on | off: the host's GPU for the cameras (see match.gpu)
    public_logs: Path | None = None  # credentials.json-style target for the public logs

    def team(self, color: Color) -> TeamRef:
        return self.red if color == "red" else self.blue

    @property
    def max_players(self) -> int:
        return MAX_PLAYERS[self.field_class]


@dataclass(frozen=True, slots=True, kw_only=True)
class EcrAuth:
    region: str
    access_id: str | None = None
    access_secret: str | None = field(default=None, repr=False)


@dataclass(frozen=True, slots=True, kw_only=True)
class RegistryAuth:
    """How to log in to the team's registry: a password, a password in an env var, or ECR."""

    username: str | None = None
    password: str | None = field(default=None, repr=False)
    password_env: str | None = None
    ecr: EcrAuth | None = None

    def password_from(self, environ: Mapping[str, str]) -> str | None:
        """The password, read from ``environ`` when given as ``password_env``."""
        if self.password is not None:
            return self.password
        if self.password_env is not None:
            return environ.get(self.password_env)
        return None


@dataclass(frozen=True, slots=True, kw_only=True)
class PlayerConfig:
    number: int  # 1..N
    half_time_pose: StartingPose
    reentry_pose: StartingPose
    shootout_pose: StartingPose
    goalkeeper_pose: StartingPose
    model: str  # built-in robot model, e.g. "kid-default"
    proto: str | None = None  # HLVS Webots PROTO name, kept for reference
    image_repository: str | None = None  # the player's own ``image`` or the team's
    docker_tag: str | None = None
    docker_cmd: str | None = None  # as written; see ``docker_cmd_args``

    @property
    def image(self) -> str | None:
        """``repository:tag`` (the repository alone when no dockerTag), None when unnamed."""
        if self.image_repository is None:
            return None
        if self.docker_tag is None:
            return self.image_repository
        return f"{self.image_repository}:{self.docker_tag}"

    @property
    def docker_cmd_args(self) -> tuple[str, ...]:
        """``dockerCmd`` split like a shell would (empty when absent)."""
        return tuple(shlex.split(self.docker_cmd)) if self.docker_cmd else ()


@dataclass(frozen=True, slots=True, kw_only=True)
class TeamConfig:
    """team_config.json: the HLVS team file plus image, model and registry login."""

    source: Path
    name: str
    players: tuple[PlayerConfig, ...]  # ordered by number, players[n - 1].number == n
    image: str | None = None  # default image repository for every player
    registry_auth: RegistryAuth | None = None

    @property
    def display_name(self) -> str:
        return self.name[:DISPLAY_NAME_CHARS]

    def player(self, number: int) -> PlayerConfig:
        return self.players[number - 1]


@dataclass(frozen=True, slots=True, kw_only=True)
class LoadedTeam:
    team: TeamConfig
    warnings: tuple[Problem, ...] = ()


@dataclass(frozen=True, slots=True, kw_only=True)
class LoadedGame:
    """game.json with the two team files it references and every warning found."""

    game: GameConfig
    red: TeamConfig
    blue: TeamConfig
    warnings: tuple[Problem, ...] = ()

    def team(self, color: Color) -> TeamConfig:
        return self.red if color == "red" else self.blue


__all__ = [
    "COLORS",
    "Color",
    "DEFAULT_MODEL",
    "DISPLAY_NAME_CHARS",
    "EcrAuth",
    "FieldClass",
    "GameConfig",
    "GameType",
    "Limits",
    "LoadedGame",
    "LoadedTeam",
    "MAX_PLAYERS",
    "PlayerConfig",
    "RegistryAuth",
    "SideChoice",
    "StartingPose",
    "SteppingMode",
    "TeamConfig",
    "TeamRef",
    "Timing",
]
