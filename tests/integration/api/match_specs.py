"""Short match specs for runtime tests (free loopback ports, short timings)."""

from __future__ import annotations

from dataclasses import replace
from typing import Any

from contracts.match_spec import MatchSpec, NetworkSpec, PlayerSpec, Pose, TeamSpec, TimingSpec
from tests.integration.api.harness import free_ports


def _player(number: int, port: int) -> PlayerSpec:
    pose = Pose(x_m=-1.0 - number, y_m=-3.2 if number % 2 else 3.2, yaw_rad=1.57)
    return PlayerSpec(
        number=number,
        model="kid-default",
        port=port,
        half_time_pose=pose,
        reentry_pose=pose,
        shootout_pose=Pose(x_m=2.75, y_m=0.0, yaw_rad=0.0),
        goalkeeper_pose=Pose(x_m=-4.4, y_m=0.0, yaw_rad=0.0),
        goalkeeper=number == 1,
    )


def short_spec(
    *, players: int = 1, stepping: str = "lockstep", seed: int = 7, **overrides: Any
) -> MatchSpec:
    ports = free_ports(2 * players + 3)
    red = TeamSpec(
        color="red", team_id=8, name="Red", hosts=("127.0.0.1",),
        players=tuple(_player(n, ports[n - 1]) for n in range(1, players + 1)),
    )  # fmt: skip
    blue = TeamSpec(
        color="blue", team_id=25, name="Blue", hosts=("127.0.0.1",),
        players=tuple(_player(n, ports[players + n - 1]) for n in range(1, players + 1)),
    )  # fmt: skip
    timing = TimingSpec(
        half_duration_s=1.0,
        ready_duration_s=0.5,
        set_to_play_s=0.2,
        wait_before_first_ready_real_s=0.3,
        half_time_break_real_s=0.2,
        end_of_game_real_s=0.2,
        max_duration_real_s=120.0,
    )
    network = NetworkSpec(
        api_bind_host="127.0.0.1",
        gc_data_port=ports[-3],
        gc_return_port=ports[-2],
        mirror_port=ports[-1],
    )
    spec = MatchSpec(
        match_id="test-match",
        seed=seed,
        game_type="NORMAL",
        field_class="kid",
        side_left="red",
        kickoff="red",
        red=red,
        blue=blue,
        stepping=stepping,  # type: ignore[arg-type]
        maximum_real_time_factor=0.0,
        timing=timing,
        network=network,
    )
    return replace(spec, **overrides)
