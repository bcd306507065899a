"""The field's lines and the nets' cords as one mesh each for the robot cameras: the world carries
them hidden beside their boxes, the cameras' copy of the model draws the meshes instead of the
boxes, and a camera frame is the frame the boxes make (but for a few pixels where two boxes
overlap at the same depth, drawn in another order)."""

from __future__ import annotations

import mujoco
import numpy as np
import pytest

import simulator.world.camera as camera
from simulator.world import CameraRenderer, World
from simulator.world.camera import robot_camera_model
from simulator.world.merged import merged_groups

from .conftest import eight_robots

W, H = 320, 240


@pytest.fixture(scope="module")
def world() -> World:
    world = World.create(field_class="kid", robots=eight_robots(), seed=1, texture_seed=2)
    for _ in range(5):
        world.step()
    return world


def _names(model: mujoco.MjModel) -> list[str]:
    return [model.geom(g).name for g in range(model.ngeom)]


@pytest.mark.parametrize("field_class", ["kid", "adult"])
def test_the_world_carries_every_line_and_cord_twice_and_hides_the_meshes(
    field_class: str,
) -> None:
    world = World.create(field_class=field_class, robots=eight_robots()[:2], seed=1)  # type: ignore[arg-type]
    model = world.model
    names = _names(model)
    groups = {names[g]: boxes for g, boxes in merged_groups(model)}
    assert sorted(groups) == ["merged:goal_left:cord:", "merged:goal_right:cord:", "merged:line:"]
    lines = {g for g, n in enumerate(names) if n.startswith("line:")}
    cords = {side: {g for g, n in enumerate(names) if n.startswith(side) and ":cord:" in n}
             for side in ("goal_left:", "goal_right:")}  # fmt: skip
    assert set(groups["merged:line:"].tolist()) == lines and len(lines) == 70
    assert set(groups["merged:goal_left:cord:"].tolist()) == cords["goal_left:"]
    assert set(groups["merged:goal_right:cord:"].tolist()) == cords["goal_right:"]
    assert len(cords["goal_left:"]) > 100
    for g, _ in merged_groups(model):
        assert model.geom_type[g] == mujoco.mjtGeom.mjGEOM_MESH
        assert model.geom_rgba[g, 3] == 0  # every renderer of the world skips it
        assert model.geom_contype[g] == model.geom_conaffinity[g] == 0
        assert model.body_weldid[model.geom_bodyid[g]] == 0  # static, on the world body
    assert model.geom_rgba[sorted(lines), 3].min() == 1  # the video's lines stay boxes


def test_the_cameras_copy_draws_the_meshes_instead_of_the_boxes(world: World) -> None:
    cheap = robot_camera_model(world.model)
    for mesh, boxes in merged_groups(cheap):
        assert np.array_equal(cheap.geom_rgba[mesh], world.model.geom_rgba[boxes[0]])
        assert cheap.geom_rgba[mesh, 3] > 0
        assert np.all(cheap.geom_rgba[boxes, 3] == 0)
        assert np.all(world.model.geom_rgba[boxes, 3] > 0)  # the world's own model as it was
        assert world.model.geom_rgba[mesh, 3] == 0


def _frames(world: World, show: object) -> np.ndarray:
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(camera, "show_merged", show)
        renderer = CameraRenderer(world, W, H)
    with renderer:
        return np.stack([
            np.frombuffer(renderer.render(r), np.uint8).reshape(H, W, 3).astype(int)
            for r in world.robot_ids
        ])  # fmt: skip


def _hide_all(model: mujoco.MjModel) -> None:
    for _, boxes in merged_groups(model):
        model.geom_rgba[boxes, 3] = 0.0


def test_a_camera_frame_with_the_meshes_is_the_frame_with_the_boxes(world: World) -> None:
    meshes = _frames(world, camera.show_merged)
    boxes = _frames(world, lambda model: None)
    bare = _frames(world, _hide_all)  # neither: what the lines and nets add to a frame
    pixels = W * H
    for k in range(len(meshes)):
        differs = (np.abs(meshes[k] - boxes[k]).max(axis=2) > 8).sum()
        added = (np.abs(bare[k] - boxes[k]).max(axis=2) > 8).sum()
        assert added > 0.01 * pixels  # every camera sees lines or a net
        assert differs < 0.001 * pixels, (k, differs)
        assert np.abs(meshes[k] - boxes[k]).mean() < 0.02
