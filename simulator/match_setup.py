"""Build the referee's configuration from the match spec (the simulator's side of the contract)."""

from __future__ import annotations

from dataclasses import fields

from contracts.match_spec import MatchSpec, TeamSpec
from referee.config import (
    NetworkConfig,
    RefereeConfig,
    RefereePlayer,
    RefereeTeam,
    TimingConfig,
)


def _team(team: TeamSpec) -> RefereeTeam:
    return RefereeTeam(
        team_id=team.team_id,
        name=team.name,
        players=tuple(
            RefereePlayer(
                number=p.number,
                half_time_pose=p.half_time_pose,
                reentry_pose=p.reentry_pose,
                shootout_pose=p.shootout_pose,
                goalkeeper_pose=p.goalkeeper_pose,
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
        game_type=spec.game,
        field_class=spec.field,
        side_left=spec.side_left_color,
        kickoff=spec.kickoff_color,
        timing=timing,
        network=network,
        match_id=spec.match_id,
        seed=spec.seed,
    )
