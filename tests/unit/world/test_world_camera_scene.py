"""The robot cameras' cheaper scene: culling leaves the picture as it was, the depth map skips
only geoms whose shadows do not count, the map covers the turf, and the shadows of robots and
ball still fall on the turf, from MuJoCo's shadow map and as planar shadows (where a caster
stands and nowhere else, of about the map's shade)."""

from __future__ import annotations

import math

import mujoco
import numpy as np
import pytest

from contracts.ids import RobotId, TeamColor
from simulator.world import CameraRenderer, RobotPlacement, World, camera_scene
from simulator.world.camera import SHADOWS_ENV, camera_shadows, robot_camera_model
from simulator.world.camera_scene import (
    ROBOT_SHADOW_SIZE,
    PlanarShadows,
    no_shadow_geoms,
    planar_casters,
)
from simulator.world.commands import place_ball

from .conftest import eight_robots

W, H = 160, 120


@pytest.fixture(scope="module")
def world() -> World:
    world = World.create(field_class="kid", robots=eight_robots(), seed=1, texture_seed=3)
    for _ in range(5):
        world.step()
    return world


def _frames(world: World, *, shadows: str, cut: bool) -> tuple[np.ndarray, list[int]]:
    with pytest.MonkeyPatch.context() as mp:
        mp.setenv(SHADOWS_ENV, shadows)
        renderer = CameraRenderer(world, W, H)
    assert renderer.shadows == shadows
    with renderer:
        if not cut:  # every geom drawn (the decoration marks stay)
            renderer._cut.before = lambda data, camera: None  # type: ignore[method-assign]
        frames, drawn = [], []
        for robot in world.robot_ids:
            image = renderer.render(robot)
            frames.append(np.frombuffer(image, np.uint8).reshape(H, W, 3).astype(int))
            drawn.append(renderer._renderer.scene.ngeom)
    return np.stack(frames), drawn


@pytest.mark.parametrize("shadows", ["off", "map", "planar"])
def test_culling_leaves_the_picture_as_it_was(
    world: World, shadows: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(camera_scene, "MIN_RADIUS_PX", 0.0)  # what is out of view only
    cut, drawn = _frames(world, shadows=shadows, cut=True)
    whole, all_drawn = _frames(world, shadows=shadows, cut=False)
    assert max(drawn) < min(all_drawn)  # geoms were left out of every camera's scene
    assert np.abs(cut - whole).max() <= 2  # the same image (it is identical with llvmpipe)


@pytest.mark.parametrize("shadows", ["off", "planar"])
def test_geoms_smaller_than_a_pixel_are_left_out_for_a_pixel_or_two(
    world: World, shadows: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    small, drawn = _frames(world, shadows=shadows, cut=True)
    monkeypatch.setattr(camera_scene, "MIN_RADIUS_PX", 0.0)
    every, all_drawn = _frames(world, shadows=shadows, cut=True)
    assert sum(all_drawn) - sum(drawn) > 8 * len(drawn)  # cleats, mostly, left out
    changed = (np.abs(small - every).max(axis=3) > 8).sum(axis=(1, 2))
    assert changed.max() <= 0.0005 * W * H  # 9 pixels of 19,200 at most


def test_only_turf_lines_and_net_cords_skip_the_depth_map(world: World) -> None:
    model = world.model
    skipped = no_shadow_geoms(model)
    names = [model.geom(i).name for i in range(model.ngeom)]
    expected = [
        n == "turf" or n.startswith(("line:", "merged:")) or ":cord:" in n for n in names
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


@pytest.mark.parametrize("shadows", ["map", "planar"])
def test_robots_cast_shadows_on_the_turf_in_the_cameras(world: World, shadows: str) -> None:
    lit, _ = _frames(world, shadows=shadows, cut=True)
    unlit, _ = _frames(world, shadows="off", cut=True)
    darker = (unlit - lit).mean(axis=-1)
    # a shadow takes the key light off: darker patches in every camera's view, nothing brighter
    assert (darker > 10).mean(axis=(1, 2)).min() > 0.001
    assert (darker > 10).mean() > 0.004
    assert (darker < -10).mean() < 0.001


def test_planar_shadows_have_about_the_shade_and_place_of_the_maps(world: World) -> None:
    unlit, _ = _frames(world, shadows="off", cut=True)
    shaded = {kind: _frames(world, shadows=kind, cut=True)[0] for kind in ("map", "planar")}
    mask = {kind: (unlit - image).mean(axis=-1) > 10 for kind, image in shaded.items()}
    both = mask["map"] & mask["planar"]
    assert both.sum() / (mask["map"] | mask["planar"]).sum() > 0.4
    ratio = shaded["planar"][both].mean(axis=0) / shaded["map"][both].mean(axis=0)
    assert np.all(np.abs(ratio - 1) < 0.1), ratio


def test_defaults_planar_shadows_on_a_cpu_and_the_map_on_a_gpu(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    monkeypatch.delenv(SHADOWS_ENV, raising=False)
    assert camera_shadows(software_gl=True) == "planar"
    assert camera_shadows(software_gl=False) == "map"
    for wanted, kind in (("on", "planar"), ("map", "map"), ("planar", "planar"), ("off", "off")):
        monkeypatch.setenv(SHADOWS_ENV, wanted)
        assert camera_shadows(software_gl=True) == kind


def test_decorations_inside_a_body_part_cast_no_planar_shadow_of_their_own(world: World) -> None:
    names = [world.model.geom(int(g)).name for g in planar_casters(world.model)]
    red_1 = sorted(n.removeprefix("red_1/") for n in names if n.startswith("red_1/"))
    assert "torso:torso" in red_1 and "head:head" in red_1 and "leg:thigh_L" in red_1
    assert not [n for n in red_1 if "jersey" in n or "cleat" in n]
    assert "ball:geom" in names


def _ground_points(world: World, robot: RobotId) -> np.ndarray:
    """Where each pixel's ray from ``robot``'s camera meets the turf (nan above the horizon)."""
    camera = world.index.by_id[robot].camera
    data = world.data
    f = 0.5 * H / math.tan(math.radians(float(world.model.cam_fovy[camera])) / 2)
    v, u = np.mgrid[0:H, 0:W]
    local = np.stack([(u + 0.5 - W / 2) / f, -(v + 0.5 - H / 2) / f, -np.ones((H, W))], -1)
    rays = local @ data.cam_xmat[camera].reshape(3, 3).T
    origin = data.cam_xpos[camera]
    with np.errstate(divide="ignore"):
        t = np.where(rays[..., 2] < 0, -origin[2] / rays[..., 2], np.nan)
    return np.asarray(origin + t[..., None] * rays)


def test_a_planar_shadow_darkens_the_turf_beneath_a_robot_and_nowhere_else() -> None:
    caster, viewer = RobotId(TeamColor.RED, 1), RobotId(TeamColor.BLUE, 1)
    world = World.create(field_class="kid", robots=[
        RobotPlacement(id=caster, model="kid-default", x_m=-1.0, y_m=1.2, yaw_rad=0.0),
        RobotPlacement(id=viewer, model="kid-default", x_m=-0.6, y_m=-1.6, yaw_rad=1.5),
    ], seed=1, texture_seed=3)  # fmt: skip
    place_ball(world, (3.0, -3.0, 0.07), (0.0, 0.0, 0.0))  # behind the viewer
    world.step()
    with pytest.MonkeyPatch.context() as mp:
        images = {}
        for kind in ("off", "planar"):
            mp.setenv(SHADOWS_ENV, kind)
            with CameraRenderer(world, W, H) as renderer:
                image = np.frombuffer(renderer.render(viewer), np.uint8)
                images[kind] = image.reshape(H, W, 3).astype(int)
    darker = (images["off"] - images["planar"]).mean(axis=-1) > 10
    assert darker.sum() > 30
    ground = _ground_points(world, viewer)[darker]
    assert not np.isnan(ground).any()  # only the turf darkens
    # each darkened point lies within the shadow of a caster: its bounding sphere flattened
    # along the light onto the turf (a 3 cm margin for the pixels' size)
    model, data = world.model, world.data
    key = int(np.flatnonzero(model.light_castshadow)[0])
    light = data.light_xdir[key]
    casters = planar_casters(model)
    centres = data.geom_xpos[casters] - light * (data.geom_xpos[casters, 2:3] / light[2])
    reach = model.geom_rbound[casters] / -light[2] + 0.03
    gaps = np.linalg.norm(ground[:, None, :2] - centres[None, :, :2], axis=-1) - reach
    assert (gaps.min(axis=1) <= 0).all()
    # and the caster in view is the red robot
    nearest = casters[gaps.argmin(axis=1)]
    bodies = {model.body(int(model.geom_bodyid[g])).name.split("/")[0] for g in nearest}
    assert bodies == {"red_1"}


def test_planar_shadows_need_the_turf_and_a_light_from_above() -> None:
    model = mujoco.MjModel.from_xml_string(
        '<mujoco><worldbody><light directional="true" dir="0 0 -1" castshadow="true"/>'
        '<geom type="plane" size="2 2 0.1"/><geom type="box" size="0.1 0.1 0.1" pos="0 0 1"/>'
        "</worldbody></mujoco>"
    )
    shadows = PlanarShadows(model)
    assert len(shadows.casters) == 1  # the box; the plane receives
    scene = mujoco.MjvScene(model, 10)
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    mujoco.mjv_updateScene(model, data, mujoco.MjvOption(), None, mujoco.MjvCamera(),
                           mujoco.mjtCatBit.mjCAT_ALL, scene)  # fmt: skip
    light = shadows.light(scene)
    assert light is not None
    assert light.direction @ (0, 0, -1) == pytest.approx(1)
    # an untextured plane: no turf colour to darken, no shadow drawn
    assert shadows.add(scene, data, light, np.arange(1)) == 0
