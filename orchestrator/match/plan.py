"""What one match runs: teams, robots, images, limits, and how to write the simulator's spec.

:func:`plan_from_game` builds a :class:`MatchPlan` from a validated
:class:`orchestrator.config.LoadedGame`; tests and ``hlvs scrimmage`` build it the same way from
the files they write.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path

from contracts import AdmissionRecord, MatchSpec
from orchestrator.config import Limits, LoadedGame, PlayerConfig, TeamConfig
from orchestrator.config.robot_models import is_model_path
from orchestrator.config.spec import to_match_spec
from orchestrator.match.gpu import GpuOrigin

SpecBuilder = Callable[[Mapping[str, tuple[str, ...]], str | None], MatchSpec]
"""(robot addresses per color, telemetry endpoint or None) -> the match's ``match_spec.json``."""


@dataclass(frozen=True, slots=True, kw_only=True)
class RobotPlan:
    color: str  # red | blue
    number: int  # 1..N
    port: int  # robot API port on the simulator
    image: str | None  # None: no image named (the robot is spawned without a controller)
    command: tuple[str, ...] | None = None  # None: the image's default command
    team_id: int | None = None  # the team's GameController number (ROBOCUP_TEAM_ID)

    @property
    def key(self) -> str:
        return f"{self.color}-{self.number}"


@dataclass(frozen=True, slots=True, kw_only=True)
class TeamPlan:
    color: str
    name: str
    robots: tuple[RobotPlan, ...]


@dataclass(frozen=True, slots=True, kw_only=True)
class RegistryAccess:
    """What pulling a match's team images needs: each team's file (its players' images,
    its registry credentials) and whether the images must come from a registry
    (``registry_images`` of game.json)."""

    red: TeamConfig
    blue: TeamConfig
    registry_only: bool = False

    def team(self, color: str) -> TeamConfig:
        return self.red if color == "red" else self.blue


@dataclass(frozen=True, slots=True, kw_only=True)
class MatchPlan:
    match_id: str
    seed: int
    red: TeamPlan
    blue: TeamPlan
    spec_builder: SpecBuilder
    limits: Limits = field(default_factory=Limits)
    allow_internet: bool = False
    official: bool = False
    gpu: str = "auto"  # auto | on | off (orchestrator.match.gpu)
    gpu_origin: GpuOrigin = field(default_factory=GpuOrigin)  # where ``gpu`` was set
    game_file: str = "game.json"  # where the match's settings were read (for their errors)
    admission: AdmissionRecord | None = None  # the admission verdict, copied into results
    grace_period_s: float = 120.0
    telemetry: bool = True  # ask the simulator for zenoh telemetry on the control network
    telemetry_silence_s: float = 30.0  # fail the match when telemetry stays silent this long
    mirror_port: int = 3737
    versions: Mapping[str, str] = field(default_factory=dict)
    model_dirs: tuple[Path, ...] = ()  # team robot model packages the simulator must read
    # the teams' registries, to pull their images from (None: the engine has them already)
    registry: RegistryAccess | None = None

    @property
    def teams(self) -> tuple[TeamPlan, TeamPlan]:
        return (self.red, self.blue)

    @property
    def robots(self) -> tuple[RobotPlan, ...]:
        return self.red.robots + self.blue.robots


def _robot(color: str, player: PlayerConfig, port: int, team_id: int) -> RobotPlan:
    args = player.docker_cmd_args
    return RobotPlan(
        color=color, number=player.number, port=port, image=player.image,
        command=args if args else None, team_id=team_id,
    )


def plan_from_game(loaded: LoadedGame, *, grace_period_s: float | None = None) -> MatchPlan:
    game = loaded.game
    teams = []
    for color in ("red", "blue"):
        ref = game.team(color)
        cfg = loaded.team(color)
        robots = tuple(_robot(color, p, ref.port(p.number), ref.team_id) for p in cfg.players)
        teams.append(TeamPlan(color=color, name=cfg.display_name, robots=robots))

    def build(addresses: Mapping[str, tuple[str, ...]], telemetry: str | None) -> MatchSpec:
        return match_spec(loaded, addresses, telemetry)

    return MatchPlan(
        match_id=game.match_id,
        seed=game.seed,
        red=teams[0],
        blue=teams[1],
        spec_builder=build,
        limits=game.limits,
        allow_internet=game.allow_internet,
        official=game.official,
        gpu=game.gpu,
        gpu_origin=GpuOrigin(file=str(game.source), pointer="/gpu"),
        game_file=str(game.source),
        grace_period_s=game.timing.grace_period_s if grace_period_s is None else grace_period_s,
        registry=RegistryAccess(red=loaded.red, blue=loaded.blue,
                                registry_only=game.registry_images),
        model_dirs=tuple(
            dict.fromkeys(
                Path(p.model)
                for color in ("red", "blue")
                for p in loaded.team(color).players
                if is_model_path(p.model)
            )
        ),
    )


def match_spec(
    loaded: LoadedGame, addresses: Mapping[str, tuple[str, ...]], telemetry: str | None
) -> MatchSpec:
    """The match spec from the config layer, with this run's addresses: the robots' fixed IPs
    are the team's allowed hosts (game.json's ``hosts`` are not: each robot has an address of
    its own here) and GameController targets."""
    return to_match_spec(
        loaded, robot_addresses={c: list(a) for c, a in addresses.items()},
        telemetry_listen=telemetry, game_hosts=False,
    )


def robots_in_game(game_path: Path) -> int:
    """How many robots the match of ``game_path`` plays (both teams): the nodes a
    league-placement job asks for besides the simulator's."""
    from orchestrator.config.loader import load_game

    return len(plan_from_game(load_game(game_path)).robots)


def per_robot_rate_mb_s(team_rate_mb_s: float, n_robots: int) -> float:
    return team_rate_mb_s / max(1, n_robots) if math.isfinite(team_rate_mb_s) else team_rate_mb_s


__all__ = [
    "MatchPlan",
    "RobotPlan",
    "SpecBuilder",
    "TeamPlan",
    "match_spec",
    "per_robot_rate_mb_s",
    "plan_from_game",
    "robots_in_game",
]
