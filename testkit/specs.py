"""Match specs for tests that run the orchestrator without its configuration layer.

:func:`match_spec` builds a real :class:`~contracts.match_spec.MatchSpec` (the one type the
simulator reads) from robot numbers and ports, with the run's robot addresses and telemetry
endpoint, so test doubles of the simulator read the same document a real match writes.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence

from contracts.geometry import Pose
from contracts.match_spec import (
    Color,
    MatchSpec,
    NetworkSpec,
    PlayerSpec,
    SteppingMode,
    TeamSpec,
)


def _players(ports: Mapping[int, int]) -> tuple[PlayerSpec, ...]:
    return tuple(
        PlayerSpec(
            number=number, model="kid-default", port=port,
            half_time_pose=Pose(x_m=-0.6 - 0.9 * number, y_m=-3.1, yaw_rad=math.pi / 2),
            reentry_pose=Pose(x_m=-3.0, y_m=-3.1, yaw_rad=math.pi / 2),
            shootout_pose=Pose(x_m=2.75, y_m=0.0, yaw_rad=0.0),
            goalkeeper_pose=Pose(x_m=-4.4, y_m=0.0, yaw_rad=0.0),
            goalkeeper=number == 1,
        )
        for number, port in sorted(ports.items())
    )  # fmt: skip


def match_spec(
    *,
    match_id: str,
    seed: int,
    ports: Mapping[str, Mapping[int, int]],
    addresses: Mapping[str, Sequence[str]],
    telemetry: str | None,
    stepping: SteppingMode = "async",
) -> MatchSpec:
    """A kid-size NORMAL match; ``ports``: color -> {player number: robot API port};
    ``addresses``: color -> robot addresses (the team's hosts and GameController targets)."""

    def team(color: Color, team_id: int) -> TeamSpec:
        hosts = tuple(addresses.get(color, ()))
        return TeamSpec(color=color, team_id=team_id, name=f"{color} team",
                        players=_players(ports.get(color, {})), hosts=hosts,
                        robot_addresses=hosts)

    return MatchSpec(
        match_id=match_id, seed=seed, game_type="NORMAL", field_class="kid", side_left="red",
        kickoff="red", red=team("red", 8), blue=team("blue", 25), stepping=stepping,
        network=NetworkSpec(telemetry_listen=telemetry),
    )  # fmt: skip


__all__ = ["match_spec"]
