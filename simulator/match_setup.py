"""Build the referee's configuration from the match spec (the simulator's side of the contract)."""

from __future__ import annotations

from dataclasses import fields

from contracts import MatchSpec, send_period_s
from referee import NetworkConfig, RefereeConfig, TimingConfig


def referee_config(spec: MatchSpec) -> RefereeConfig:
    """The :class:`RefereeConfig` of a match: teams, poses, timing and the UDP ports; RGme goes
    out every 500 ms, or every 50 ms when the game is not paced to real time, as the league's
    GameController with ``--fast`` (:func:`contracts.send_period_s`)."""
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
        send_rate_hz=1.0 / send_period_s(spec.maximum_real_time_factor),
    )
    return RefereeConfig(
        red=spec.red,
        blue=spec.blue,
        game_type=spec.game,
        field_class=spec.field,
        side_left=spec.side_left_color,
        kickoff=spec.kickoff_color,
        timing=timing,
        network=network,
        match_id=spec.match_id,
        seed=spec.seed,
    )
