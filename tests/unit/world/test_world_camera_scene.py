"""The robot cameras' cheaper scene: culling leaves the picture as it was, the depth map skips
only geoms whose shadows do not count, the map covers the turf, and the shadows of robots and
ball still fall on the turf."""

from __future__ import annotations

import math

import numpy as np
import pytest

from simulator.world import CameraRenderer, World
from simulator.world.camera import SHADOWS_ENV, robot_camera_model
from simulator.world.camera_scene import ROBOT_SHADOW_SIZE, no_shadow_geoms

from .conftest import eight_robots

W, H = 160, 120


@pytest.fixture(scope="module")
def world() -> World:
    world = World.create(field_class="kid", robots=eight_robots(), seed=1, texture_seed=3)
    for _ in range(5):
        world.step()
    return world


def _frames(world: World, *, shadows: bool, cut: bool) -> tuple[np.ndarray, list[int]]:
    with pytest.MonkeyPatch.context() as mp:
        mp.setenv(SHADOWS_ENV, "on" if shadows else "off")
        renderer = CameraRenderer(world, W, H)
    with renderer:
        if not cut:  # every geom drawn (the decoration marks stay)
            renderer._cut.before = lambda data, camera: None  # type: ignore[method-assign]
        frames, drawn = [], []
        for robot in world.robot_ids:
            image = renderer.render(robot)
            frames.append(np.frombuffer(image, np.uint8).reshape(H, W, 3).astype(int))
            drawn.append(renderer._renderer.scene.ngeom)
    return np.stack(frames), drawn


@pytest.mark.parametrize("shadows", [False, True])
def test_culling_leaves_the_picture_as_it_was(world: World, shadows: bool) -> None:
    cut, drawn = _frames(world, shadows=shadows, cut=True)
    whole, all_drawn = _frames(world, shadows=shadows, cut=False)
    assert max(drawn) < min(all_drawn)  # geoms were left out of every camera's scene
    assert np.abs(cut - whole).max() <= 2  # the same image (it is identical with llvmpipe)


def test_only_turf_lines_and_net_cords_skip_the_depth_map(world: World) -> None:
    model = world.model
    skipped = no_shadow_geoms(model)
    names = [model.geom(i).name for i in range(model.ngeom)]
    expected = [
        n == "turf" or n.startswith("line:") or "_cord" in n for n in names
    ]  # fmt: skip
    wrong = [n for n, s, e in zip(names, skipped, expected, strict=True) if s != e]
    assert not wrong
    assert sum(expected) > 100


def test_the_cameras_depth_map_covers_the_turf_at_their_own_size(world: World) -> None:
    cheap = robot_camera_model(world.model)
    turf = world.model.geom("turf").id
    assert cheap.vis.quality.shadowsize == ROBOT_SHADOW_SIZE
    half_diagonal = math.hypot(*world.model.geom_size[turf, :2])
    covered = cheap.vis.map.shadowclip * cheap.stat.extent
    assert half_diagonal < covered < 1.2 * half_diagonal + 0.5
    # the world's own model (the match video, hlvs render) keeps its map and turf grid
    assert world.model.vis.quality.shadowsize == 2048
    assert world.model.vis.map.shadowclip == 1.0
    assert world.model.geom_size[turf, 2] < cheap.geom_size[turf, 2]


def test_robots_cast_shadows_on_the_turf_in_the_cameras(world: World) -> None:
    lit, _ = _frames(world, shadows=True, cut=True)
    unlit, _ = _frames(world, shadows=False, cut=True)
    darker = (unlit - lit).mean(axis=-1)
    # a shadow takes the key light off: darker patches in every camera's view, nothing brighter
    assert (darker > 10).mean(axis=(1, 2)).min() > 0.001
    assert (darker > 10).mean() > 0.004
    assert (darker < -10).mean() < 0.001
