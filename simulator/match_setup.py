"""Build the referee's configuration from the match spec (the simulator's side of the contract)."""

from __future__ import annotations

from dataclasses import fields

from referee.config import (
    GameType,
    NetworkConfig,
    PlayerConfig,
    RefereeConfig,
    TeamConfig,
    TimingConfig,
)
from referee.config import Pose as RefereePose
from referee.field import FieldClass
from referee.snapshot import TeamColor
from simulator.spec import MatchSpec, Pose, TeamSpec


def _pose(pose: Pose) -> RefereePose:
    return RefereePose(x_m=pose.x_m, y_m=pose.y_m, yaw_rad=pose.yaw_rad)


def _team(team: TeamSpec) -> TeamConfig:
    return TeamConfig(
        team_id=team.team_id,
        name=team.name,
        players=tuple(
            PlayerConfig(
                number=p.number,
                half_time_pose=_pose(p.half_time_pose),
                reentry_pose=_pose(p.reentry_pose),
                shootout_pose=_pose(p.shootout_pose),
                goalkeeper_pose=_pose(p.goalkeeper_pose),
                goalkeeper=p.goalkeeper,
            )
            for p in team.players
        ),
        robot_addresses=team.robot_addresses,
    )


def referee_config(spec: MatchSpec) -> RefereeConfig:
    """The :class:`RefereeConfig` of a match: teams, poses, timing and the UDP ports."""
    timing_names = {f.name for f in fields(TimingConfig)}
    timing = TimingConfig(
        **{
            f.name: getattr(spec.timing, f.name)
            for f in fields(spec.timing)
            if f.name in timing_names
        }
    )
    network = NetworkConfig(
        bind_host=spec.network.api_bind_host,
        gc_data_port=spec.network.gc_data_port,
        gc_return_port=spec.network.gc_return_port,
        mirror_port=spec.network.mirror_port,
    )
    return RefereeConfig(
        red=_team(spec.red),
        blue=_team(spec.blue),
        game_type=GameType(spec.game_type),
        field_class=FieldClass(spec.field_class),
        side_left=TeamColor(spec.side_left),
        kickoff=TeamColor(spec.kickoff),
        timing=timing,
        network=network,
        match_id=spec.match_id,
        seed=spec.seed,
    )
