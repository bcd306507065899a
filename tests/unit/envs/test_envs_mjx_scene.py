"""The MJX variant's collision bits (no JAX needed): the goals' collision geoms meet the ball
only, and the nets' cords, which the cameras see and nothing touches, stay without contacts."""

from __future__ import annotations

from envs.mjx_world import GOAL_BIT, mjx_scene


def test_goal_bits_go_to_the_goals_collision_geoms_and_not_to_the_cords() -> None:
    model = mjx_scene().model
    goal = [g for g in range(model.ngeom)
            if model.geom(g).name.startswith(("goal_left", "goal_right"))]  # fmt: skip
    cords = [g for g in goal if ":cord:" in model.geom(g).name]
    solid = [g for g in goal if g not in cords]
    assert len(cords) > 200 and len(solid) >= 10
    assert all(int(model.geom_contype[g]) == 0 and int(model.geom_conaffinity[g]) == 0
               for g in cords)  # fmt: skip
    ball_bit = int(model.geom("ball:geom").contype[0])
    assert all(int(model.geom_contype[g]) == GOAL_BIT for g in solid)
    assert all(int(model.geom_conaffinity[g]) == ball_bit for g in solid)
