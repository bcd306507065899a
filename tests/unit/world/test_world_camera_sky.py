"""The robot cameras sample the sky without mipmaps only where it is magnified: the same
frames, bit for bit, at 320x240; at 160x120 (minified) the sky keeps its mipmaps."""

from __future__ import annotations

import mujoco
import numpy as np
import pytest
from OpenGL import GL

from simulator.world import CameraRenderer, World
from simulator.world.camera_model import focal_px

from .conftest import eight_robots


def _frames(renderer: CameraRenderer, world: World) -> np.ndarray:
    shape = (renderer.height, renderer.width, 3)
    return np.stack([np.frombuffer(renderer.render(r), np.uint8).reshape(shape)
                     for r in world.robot_ids])  # fmt: skip


def _sky_filters(renderer: CameraRenderer, wanted: int | None = None) -> list[int]:
    """The sky textures' minifying filters (set to ``wanted`` first, when given)."""
    inner = renderer._renderer
    inner._gl_context.make_current()
    mjr, model = inner._mjr_context, inner.model
    filters = []
    for i in range(model.ntex):
        if int(model.tex_type[i]) == 2:  # mjTEXTURE_SKYBOX
            GL.glBindTexture(GL.GL_TEXTURE_CUBE_MAP, int(mjr.texture[i]))
            if wanted is not None:
                GL.glTexParameteri(GL.GL_TEXTURE_CUBE_MAP, GL.GL_TEXTURE_MIN_FILTER, wanted)
            filters.append(int(GL.glGetTexParameteriv(GL.GL_TEXTURE_CUBE_MAP,
                                                      GL.GL_TEXTURE_MIN_FILTER)))  # fmt: skip
    return filters


@pytest.mark.parametrize("texture_seed", [3, 16])  # a stadium's and a town's skyline
def test_a_magnified_sky_is_drawn_the_same_without_mipmaps(texture_seed: int) -> None:
    world = World.create(field_class="kid", robots=eight_robots(), seed=1,
                         texture_seed=texture_seed)  # fmt: skip
    for _ in range(5):
        world.step()
    with CameraRenderer(world, 320, 240) as renderer:
        camera = world.index.by_id[world.robot_ids[0]].camera
        assert focal_px(240, float(world.model.cam_fovy[camera])) > 250  # 279 px a radian
        assert renderer.linear_sky
        assert _sky_filters(renderer) == [GL.GL_LINEAR]
        fast = _frames(renderer, world)
        assert _sky_filters(renderer, GL.GL_LINEAR_MIPMAP_LINEAR) == [GL.GL_LINEAR_MIPMAP_LINEAR]
        mipmapped = _frames(renderer, world)
        renderer._renderer.scene.flags[mujoco.mjtRndFlag.mjRND_SKYBOX] = False
        skyless = _frames(renderer, world)
    np.testing.assert_array_equal(fast, mipmapped)
    seen = (skyless != fast).any(axis=3).sum(axis=(1, 2))
    assert (seen > 320 * 240 // 10).all(), seen  # every frame shows the sky


def test_a_minified_sky_keeps_its_mipmaps() -> None:
    world = World.create(field_class="kid", robots=eight_robots()[:1], seed=1, texture_seed=3)
    with CameraRenderer(world, 160, 120) as renderer:
        assert not renderer.linear_sky  # 140 px a radian against 192 texels
        assert _sky_filters(renderer) == [GL.GL_LINEAR_MIPMAP_LINEAR]
