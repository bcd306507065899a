"""The match spec: everything the simulator process needs, resolved, in one JSON file.

The orchestrator reads ``game.json`` and the team files (through its config layer), resolves every
default and random choice (sides and kick-off from the seed), and writes ``match_spec.json``
(``MatchSpec.write``); the simulator process (``python -m simulator run --spec FILE``) reads only
this file (``MatchSpec.load``). Poses are given as in HLVS team files: as if the team played on
the left half (x < 0); the world and the referee mirror them for the team on the right
(:meth:`contracts.geometry.Pose.mirrored`).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from enum import StrEnum
from typing import ClassVar, Literal

from contracts.codec import Versioned
from contracts.field import FieldClass
from contracts.geometry import Pose
from contracts.ids import TeamColor
from contracts.timing import MIN_PLAYING_S, REMOVAL_PENALTY_S, SET_TO_PLAY_S

SPEC_VERSION = 1

SteppingMode = Literal["async", "lockstep", "pipelined"]
SensorMode = Literal["league", "ideal"]
Color = Literal["red", "blue"]  # contracts.ids.TeamColor values
GameTypeName = Literal["NORMAL", "KNOCKOUT", "PENALTY"]  # GameType values
FieldClassName = Literal["kid", "adult"]  # contracts.field.FieldClass values


class GameType(StrEnum):
    NORMAL = "NORMAL"  # round robin: two halves, draws allowed
    KNOCKOUT = "KNOCKOUT"  # play-off: overtime 2 x 300 s, then a penalty shoot-out
    PENALTY = "PENALTY"  # starts with the penalty shoot-out


@dataclass(frozen=True, slots=True, kw_only=True)
class PlayerSpec:
    number: int  # 1..N
    model: str  # built-in robot model name, e.g. "kid-default"
    port: int  # robot API TCP port
    half_time_pose: Pose
    reentry_pose: Pose
    shootout_pose: Pose
    goalkeeper_pose: Pose  # used only while this robot is the GameController's goalkeeper
    goalkeeper: bool = False  # marked goalkeeper at the start (league default: player 1)


@dataclass(frozen=True, slots=True, kw_only=True)
class TeamSpec:
    color: Color
    team_id: int  # GameController team number
    name: str
    players: tuple[PlayerSpec, ...]
    hosts: tuple[str, ...]  # peer addresses allowed on this team's API ports (and mirror members)
    robot_addresses: tuple[str, ...] = ()  # where RGme is sent (UDP 3838); robot n at index n-1

    def player(self, number: int) -> PlayerSpec:
        for player in self.players:
            if player.number == number:
                return player
        raise KeyError(number)


@dataclass(frozen=True, slots=True, kw_only=True)
class TimingSpec:
    """Game timing. ``*_real_s`` are wall-clock waits; everything else is simulated time.

    ``half_duration_s`` is game-clock time, as the league's GameController counts it
    (``AdvancedData.getRemainingGameTime``): the clock stands still in READY and SET before the
    first kick-off of a half (and of an overtime half), so that PLAYING starts with the full
    half; once the half has been played in, READY and SET after a goal count as played (no
    added time)."""

    half_duration_s: float = 600.0
    overtime_half_duration_s: float = 300.0
    ready_duration_s: float = 45.0
    set_to_play_s: float = SET_TO_PLAY_S
    wait_before_first_ready_real_s: float = 120.0
    half_time_break_real_s: float = 15.0
    removal_penalty_s: float = REMOVAL_PENALTY_S
    end_of_game_real_s: float = 5.0
    max_duration_real_s: float | None = None  # stop the game after this wall time
    minimum_play_s: float = MIN_PLAYING_S  # less PLAYING: not played (0: not meant to play)


@dataclass(frozen=True, slots=True, kw_only=True)
class NetworkSpec:
    api_bind_host: str = "0.0.0.0"
    gc_data_port: int = 3838
    gc_return_port: int = 3939
    mirror_port: int = 3737
    telemetry_listen: str | None = None  # zenoh endpoint, e.g. "tcp/172.30.0.2:7447"; None = off
    team_quota_mb_s: float = 350.0  # per real second per team, split evenly per robot
    rendering_quota_mb_s: float = 350.0  # per simulated second per team
    blocking_send: bool = False  # True restores the HLVS behaviour (a slow reader stalls the step)
    send_queue_messages: int = 64


@dataclass(frozen=True, slots=True, kw_only=True)
class MatchSpec(Versioned):
    """``match_spec.json``: written by the orchestrator, read by the simulator."""

    VERSION: ClassVar[int] = SPEC_VERSION
    KIND: ClassVar[str] = "match spec"

    match_id: str
    seed: int
    game_type: GameTypeName
    field_class: FieldClassName
    side_left: Color  # team on x < 0 in the first half
    kickoff: Color  # team with the first kick-off
    red: TeamSpec
    blue: TeamSpec
    stepping: SteppingMode = "async"
    maximum_real_time_factor: float = 1.0  # <= 0: as fast as possible
    physics_dt_s: float = 0.002
    lockstep_deadline_ms: float = 50.0
    lockstep_time_bank_ms: float = 5000.0
    timing: TimingSpec = field(default_factory=TimingSpec)
    network: NetworkSpec = field(default_factory=NetworkSpec)
    record_video: str | None = None  # file name inside the output folder, e.g. "match.mp4"
    recorder_rate_hz: float = 25.0
    texture_seed: int | None = None  # the look (turf, ball, background, light); None: ``seed``
    sensors: SensorMode = "league"  # "ideal": exact sensors and camera images
    camera_motion_blur: bool = False
    version: int = SPEC_VERSION

    @property
    def game(self) -> GameType:
        return GameType(self.game_type)

    @property
    def side_left_color(self) -> TeamColor:
        return TeamColor(self.side_left)

    @property
    def kickoff_color(self) -> TeamColor:
        return TeamColor(self.kickoff)

    @property
    def field(self) -> FieldClass:
        return FieldClass(self.field_class)

    def team(self, color: TeamColor | str) -> TeamSpec:
        return self.red if color == TeamColor.RED else self.blue


__all__ = [
    "SPEC_VERSION",
    "GameType",
    "MatchSpec",
    "NetworkSpec",
    "PlayerSpec",
    "Pose",
    "Color",
    "FieldClassName",
    "GameTypeName",
    "SensorMode",
    "SteppingMode",
    "TeamSpec",
    "TimingSpec",
]
