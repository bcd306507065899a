"""The MJCF world matches the rule-book numbers of both field classes."""

from __future__ import annotations

import numpy as np
import pytest

from contracts.field import ADULT_FIELD, KID_FIELD, FieldGeometry
from simulator.errors import UnknownModelError
from simulator.world import (
    MOTOR_NAMES,
    RobotPlacement,
    World,
    known_models,
    robot_model,
)
from simulator.world.servos import servo
from tests.unit.world.conftest import RED_1


def _geom(world: World, name: str) -> tuple[np.ndarray, np.ndarray]:
    g = world.model.geom(name)
    return world.data.geom_xpos[g.id].copy(), world.model.geom_size[g.id].copy()


@pytest.mark.parametrize(("field_class", "geometry"), [("kid", KID_FIELD), ("adult", ADULT_FIELD)])
def test_pitch_goals_and_ball_follow_the_rules(field_class: str, geometry: FieldGeometry) -> None:
    world = World.create(field_class=field_class, robots=[], seed=1)  # type: ignore[arg-type]
    assert world.field is geometry
    _, turf = _geom(world, "turf")
    assert turf[0] == pytest.approx(geometry.half_length_m + 1.0)
    assert turf[1] == pytest.approx(geometry.half_width_m + 1.0)
    assert world.model.geom("turf").friction[0] == pytest.approx(0.5)
    for name, sign in (("goal_left", -1.0), ("goal_right", 1.0)):
        post_a, size = _geom(world, f"{name}:post_a")
        post_b, _ = _geom(world, f"{name}:post_b")
        radius = size[0]
        assert radius == pytest.approx(geometry.goal_post_radius_m)
        assert post_a[0] == pytest.approx(sign * geometry.half_length_m)
        inner_width = (post_a[1] - post_b[1]) - 2 * radius
        assert inner_width == pytest.approx(geometry.goal_width_m)
        bar, bar_size = _geom(world, f"{name}:crossbar")
        assert bar[2] - bar_size[0] == pytest.approx(geometry.goal_height_m)
        back, back_size = _geom(world, f"{name}:net_back")  # turned: its thin side is local z
        assert abs(back[0]) - back_size[2] == pytest.approx(
            geometry.half_length_m + geometry.goal_depth_m
        )
    ball = world.model.geom("ball:geom")
    assert ball.size[0] == pytest.approx(geometry.ball_radius_m)
    assert world.model.body("ball").mass[0] == pytest.approx(geometry.ball_mass_kg)
    mark, _ = _geom(world, "line:penalty_mark_r_x")
    assert mark[0] == pytest.approx(geometry.half_length_m - geometry.penalty_mark_distance_m)
    circle, _ = _geom(world, "line:circle_0")
    assert np.hypot(circle[0], circle[1]) == pytest.approx(geometry.centre_circle_radius_m)
    lines = [world.model.geom(i) for i in range(world.model.ngeom)]
    assert all(g.contype[0] == 0 for g in lines if g.name.startswith("line:"))


@pytest.mark.parametrize("name", ["kid-default", "adult-default"])
def test_robot_models_fit_their_class(name: str) -> None:
    model = robot_model(name)
    geometry = KID_FIELD if model.field_class == "kid" else ADULT_FIELD
    height = model.geometry.total_height_m
    assert geometry.robot_min_height_m <= height <= geometry.robot_max_height_m
    assert model.motor_names == MOTOR_NAMES
    if name == "kid-default":
        assert 4.0 <= model.geometry.total_mass_kg <= 5.5
        assert all(2.0 <= m.max_torque_nm <= 10.0 for m in model.motors)
    for m in model.motors:  # every motor a catalogue servo with its datasheet figures
        entry = servo(m.servo)
        assert (m.max_torque_nm, m.max_velocity_rad_s) == (
            entry.stall_torque_nm,
            entry.no_load_speed_rad_s,
        )


def test_unknown_model_lists_the_known_ones() -> None:
    assert known_models() == ("adult-default", "kid-default")
    placement = RobotPlacement(id=RED_1, model="nao-v6", x_m=0, y_m=0, yaw_rad=0)
    with pytest.raises(UnknownModelError) as caught:
        World.create(field_class="kid", robots=[placement], seed=1)
    assert caught.value.name == "nao-v6"
    assert caught.value.known == ["adult-default", "kid-default"]
    assert "kid-default" in str(caught.value)


def test_robot_bodies_and_joints_are_named_per_player(one_robot_world: World) -> None:
    model = one_robot_world.model
    assert model.body("red_1/torso").id > 0
    for motor in MOTOR_NAMES:
        assert model.joint(f"red_1/{motor}").type[0] == 3  # hinge
        assert model.actuator(f"red_1/{motor}").id >= 0
    assert one_robot_world.robot_ids == (RED_1,)
