"""Referee configuration: everything the referee needs, resolved, as frozen dataclasses.

The simulator maps the ``contracts.match_spec.MatchSpec`` onto :class:`RefereeConfig`: the teams
are the spec's own :class:`~contracts.match_spec.TeamSpec` (players, poses, robot addresses); the
referee adds its rule book's durations (:class:`TimingConfig`) and its UDP details
(:class:`NetworkConfig`). Poses are :class:`contracts.geometry.Pose`, given as in HLVS team files:
as if the team played on the left half (x < 0); the referee places them with
:meth:`~contracts.geometry.Pose.on_side`.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from contracts import (
    FieldClass,
    FieldGeometry,
    GameType,
    RobotId,
    TeamColor,
    TeamSpec,
    TimingSpec,
    field_for,
)


@dataclass(frozen=True, slots=True, kw_only=True)
class TimingConfig(TimingSpec):
    """The match spec's timing plus the rule book's own durations. ``*_real_s`` are wall-clock
    waits; everything else is simulated time."""

    shootout_set_to_play_s: float = 15.0
    kickoff_blocked_s: float = 10.0  # ball in play after this or a 5 cm move
    set_play_phase0_s: float = 5.0  # robots still, ball placed
    set_play_ready_s: float = 15.0  # phase 1: robots position (penalty kick: twice this)
    set_play_prepare_s: float = 5.0  # phase 2: robots freeze
    dropped_ball_s: float = 120.0
    fallen_s: float = 20.0
    outside_turf_s: float = 20.0
    inactive_goalkeeper_s: float = 20.0
    shootout_kick_s: float = 60.0
    status_period_real_s: float = 20.0


@dataclass(frozen=True, slots=True, kw_only=True)
class NetworkConfig:
    bind_host: str = "0.0.0.0"
    gc_data_port: int = 3838
    gc_return_port: int = 3939
    mirror_port: int = 3737
    send_rate_hz: float = 2.0  # 20 when not paced to real time (contracts.send_period_s)
    mirror_max_bytes: int = 1024


@dataclass(frozen=True, slots=True, kw_only=True)
class RefereeConfig:
    red: TeamSpec  # robot_addresses: robot n at index n-1 (RGme target, mirror member)
    blue: TeamSpec
    game_type: GameType = GameType.NORMAL
    field_class: FieldClass = FieldClass.KID
    side_left: TeamColor = TeamColor.RED  # team on x < 0 in the first half
    kickoff: TeamColor = TeamColor.RED  # first kick-off (and first shooter in PENALTY games)
    timing: TimingConfig = field(default_factory=TimingConfig)
    network: NetworkConfig = field(default_factory=NetworkConfig)
    match_id: str = "match"
    seed: int = 0  # coin toss after an undecided extended shoot-out
    # the league's check of the start positions when a period's READY begins (robots off the
    # field on their own side); off for setups that start robots on the field by design (the
    # learning environments, the referee's scenario tests)
    start_positions_checked: bool = True

    @property
    def field(self) -> FieldGeometry:
        return field_for(self.field_class)

    def __post_init__(self) -> None:
        for color, team in (("red", self.red), ("blue", self.blue)):
            if team.color != color:
                raise ValueError(f"{color}: expected the {color} team, got {team.color}")

    def team(self, color: TeamColor) -> TeamSpec:
        return self.red if color is TeamColor.RED else self.blue

    def robot_ids(self) -> tuple[RobotId, ...]:
        return tuple(
            RobotId(color, player.number)
            for color in (TeamColor.RED, TeamColor.BLUE)
            for player in self.team(color).players
        )
