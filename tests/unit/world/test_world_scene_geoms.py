"""A scene's geoms as records: the layout agrees with the binding both ways, and the planar
shadows written as records are the geoms the binding writes, field by field, and the same
frames."""

from __future__ import annotations

import mujoco
import numpy as np
import pytest

from simulator.world import CameraRenderer, World
from simulator.world.camera import SHADOWS_ENV
from simulator.world.camera_scene import PlanarShadows
from simulator.world.commands import place_ball
from simulator.world.scene_geoms import geom_dtype, geom_rows

from .conftest import eight_robots

W, H = 160, 120
DECOR = int(mujoco.mjtCatBit.mjCAT_DECOR)


@pytest.fixture(scope="module")
def world() -> World:
    world = World.create(field_class="kid", robots=eight_robots(), seed=1, texture_seed=3)
    for _ in range(5):
        world.step()
    return world


def test_records_are_the_scenes_geoms_both_ways() -> None:
    model = mujoco.MjModel.from_xml_string("<mujoco><worldbody/></mujoco>")
    scene = mujoco.MjvScene(model, maxgeom=8)
    rows = geom_rows(scene)
    assert rows is not None and len(rows) == 8
    dtype = geom_dtype()
    assert dtype is not None and rows.dtype == dtype
    mujoco.mjv_initGeom(scene.geoms[5], 6, np.array([0.1, 0.2, 0.3]), np.array([1.0, 2.0, 3.0]),
                        np.eye(3).ravel(), np.array([0.5, 0.25, 1.0, 1.0], np.float32))  # fmt: skip
    scene.geoms[5].objid = 42
    assert rows["type"][5] == 6 and rows["objid"][5] == 42 and rows["dataid"][5] == -1
    assert rows["pos"][5].tolist() == [1.0, 2.0, 3.0]
    assert rows["size"][5].tolist() == pytest.approx([0.1, 0.2, 0.3])
    rows["mat"][2] = np.arange(9)
    rows["segid"][2] = 17
    rows["emission"][2] = 0.75
    geom = scene.geoms[2]
    assert geom.mat.ravel().tolist() == list(range(9))
    assert (geom.segid, geom.emission) == (17, 0.75)


def _planar(world: World) -> tuple[CameraRenderer, PlanarShadows]:
    """A camera renderer of ``world`` with planar shadows, and its shadows."""
    with pytest.MonkeyPatch.context() as mp:
        mp.setenv(SHADOWS_ENV, "planar")
        renderer = CameraRenderer(world, W, H)
    planar = renderer._cut._planar
    assert isinstance(planar, PlanarShadows)
    return renderer, planar


def _shadow_slots(world: World, records: bool) -> tuple[np.ndarray, np.ndarray]:
    """The scene's shadow geoms (as records) after one camera's frame, and all 8 frames."""
    renderer, planar = _planar(world)
    with renderer:
        scene = renderer._renderer.scene
        rows = geom_rows(scene)
        assert rows is not None
        if not records:
            planar._template = None  # geom by geom, through the binding
        else:
            assert planar._template is not None
        # stale slots, as another frame's geoms leave them: object, category, transparency
        rows["category"][:] = int(mujoco.mjtCatBit.mjCAT_STATIC)
        rows["transparent"][:] = 1
        rows["objtype"][:] = int(mujoco.mjtObj.mjOBJ_GEOM)
        rows["objid"][:] = 3
        rows["label"][:] = 0
        frames = [np.frombuffer(renderer.render(r), np.uint8) for r in world.robot_ids]
        first = renderer._renderer.scene.ngeom - 1
        while first > 0 and rows["category"][first - 1] == DECOR:
            first -= 1
        slots = rows[first : scene.ngeom].copy()
    return slots, np.stack(frames)


def test_shadows_written_as_records_are_the_bindings_geoms(world: World) -> None:
    by_records, frames = _shadow_slots(world, records=True)
    one_by_one, frames_one_by_one = _shadow_slots(world, records=False)
    assert len(by_records) >= 10  # eight robots and the ball cast shadows in the last view
    # every field alike (a label is a C string: the bytes after its end are not read)
    for name in by_records.dtype.names or ():
        if name != "label":
            assert np.array_equal(by_records[name], one_by_one[name]), name
    assert (by_records["label"][:, 0] == 0).all() and (one_by_one["label"][:, 0] == 0).all()
    assert (by_records["category"] == DECOR).all() and not by_records["transparent"].any()
    assert (by_records["objid"] == -1).all() and (by_records["segid"] == -1).all()
    assert (by_records["specular"] == 0).all()
    assert np.array_equal(frames, frames_one_by_one)


def test_the_shadows_of_one_pose_are_made_once_and_follow_a_move() -> None:
    world = World.create(field_class="kid", robots=eight_robots(), seed=1, texture_seed=3)
    renderer, planar = _planar(world)
    with renderer:
        # asked before any frame (a scene without lights yet): nothing is kept from it
        assert planar.light(renderer._renderer.scene) is None
        ball = next(
            k for k, g in enumerate(planar.casters.tolist())
            if mujoco.mj_id2name(world.model, mujoco.mjtObj.mjOBJ_GEOM, g) == "ball:geom"
        )  # fmt: skip
        renderer.render(world.robot_ids[0])
        posed = planar._last
        assert posed is not None and posed.records is not None
        assert planar.light(renderer._renderer.scene) is posed.light
        renderer.render(world.robot_ids[1])  # another camera, the same step: kept
        assert planar._last is posed
        place_ball(world, (1.0, 0.5, 0.07), (0.0, 0.0, 0.0))
        renderer.render(world.robot_ids[1])
        moved = planar._last
        assert moved is not posed and moved is not None and moved.records is not None
        shift = moved.pos[ball] - posed.pos[ball]
        # where the ball's centre falls along the light
        along = world.data.geom_xpos[planar.casters[ball]] @ moved.light.flatten.T
        assert moved.pos[ball][:2] == pytest.approx(along[:2], abs=1e-9)
        assert np.linalg.norm(shift[:2]) > 0.05
        assert moved.records["pos"][ball] == pytest.approx(moved.pos[ball], abs=1e-6)
        others = np.arange(len(planar.casters)) != ball
        assert np.array_equal(moved.pos[others], posed.pos[others])
