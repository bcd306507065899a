"""World.from_spec: each team's half-time poses, mirrored for the team on the right."""

from __future__ import annotations

import math
from dataclasses import replace

import pytest

from contracts.ids import RobotId, TeamColor
from contracts.match_spec import MatchSpec, PlayerSpec, Pose, TeamSpec
from simulator.world import World


def _team(color: str, team_id: int) -> TeamSpec:
    def player(number: int, x: float, y: float, yaw: float) -> PlayerSpec:
        pose = Pose(x_m=x, y_m=y, yaw_rad=yaw)
        return PlayerSpec(
            number=number, model="kid-default", port=10000 + number, half_time_pose=pose,
            reentry_pose=pose, shootout_pose=pose, goalkeeper_pose=pose,
        )  # fmt: skip

    return TeamSpec(
        color=color,  # type: ignore[arg-type]
        team_id=team_id,
        name=color,
        players=(player(1, -3.5, 3.1, -math.pi / 2), player(2, -1.0, -3.1, math.pi / 2)),
        hosts=("127.0.0.1",),
    )


@pytest.mark.parametrize("side_left", ["red", "blue"])
def test_from_spec_mirrors_the_team_on_the_right(side_left: str) -> None:
    spec = MatchSpec(
        match_id="spec-test", seed=9, game_type="NORMAL", field_class="kid",
        side_left=side_left, kickoff="red", red=_team("red", 1), blue=_team("blue", 2),  # type: ignore[arg-type]
    )  # fmt: skip
    world = World.from_spec(spec)
    assert world.seed == 9 and world.field.field_class.value == "kid"
    snap = world.snapshot()
    left = TeamColor(side_left)
    right = left.opponent
    one_left = snap.robot(RobotId(left, 1))
    assert one_left.position[:2] == pytest.approx((-3.5, 3.1), abs=1e-3)
    assert one_left.yaw_rad == pytest.approx(-math.pi / 2, abs=1e-3)
    one_right = snap.robot(RobotId(right, 1))
    assert one_right.position[:2] == pytest.approx((3.5, 3.1), abs=1e-3)
    # yaw -> pi - yaw: facing -y stays facing -y after mirroring x
    assert math.cos(one_right.yaw_rad) == pytest.approx(math.cos(math.pi + math.pi / 2), abs=1e-3)
    assert math.sin(one_right.yaw_rad) == pytest.approx(-1.0, abs=1e-3)
    two_right = snap.robot(RobotId(right, 2))
    assert two_right.position[:2] == pytest.approx((1.0, -3.1), abs=1e-3)
    assert len(world.robot_ids) == 4


def test_a_match_plays_with_league_sensors_and_look_unless_told_otherwise() -> None:
    spec = MatchSpec(
        match_id="spec-test", seed=9, game_type="NORMAL", field_class="kid", side_left="red",
        kickoff="red", red=_team("red", 1), blue=_team("blue", 2),
    )  # fmt: skip
    world = World.from_spec(spec)
    assert world.sensor_noise is not None and not world.camera_model.is_ideal
    assert world.look.texture_seed == 9  # the match seed when no texture seed is given
    other = World.from_spec(replace(spec, sensors="ideal", texture_seed=4))
    assert other.sensor_noise is None and other.camera_model.is_ideal
    assert other.look.texture_seed == 4
