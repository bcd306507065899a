"""The league's light: the luminosity and the background's light set make frames darker and
brighter (at least 3x across texture seeds 1..20) and tint them; lines stay below white; a
colour-based ball finder tuned on one look loses balls on the others, while the world's ground
truth (poses in the replay) does not depend on the look."""

from __future__ import annotations

from pathlib import Path

import mujoco
import numpy as np
import pytest

from referee.snapshot import PlaceBall
from simulator.world import World
from simulator.world.ball import BALL_GEOM
from simulator.world.look import (
    BACKGROUNDS,
    LINE_TEXTURE,
    Look,
    apply_look,
    lighting,
    line_image,
    look_for,
)

from .conftest import eight_robots

SEEDS = range(1, 21)


def _robot_view(renderer: mujoco.Renderer, world: World, *, x: float = -1.5) -> np.ndarray:
    """A robot's-eye frame: 0.45 m above the turf, looking along the field, 12 deg down."""
    camera = mujoco.MjvCamera()
    camera.lookat[:] = (x + 2.0, 0.0, 0.45 - 2.0 * np.tan(np.radians(12.0)))
    camera.distance, camera.azimuth, camera.elevation = 2.0 / np.cos(np.radians(12.0)), 0.0, -12.0
    renderer.update_scene(world.data, camera=camera)
    return renderer.render()


def _brightness(rgb: np.ndarray) -> float:
    return float(rgb.astype(float).mean())


@pytest.fixture(scope="module")
def world() -> World:
    return World.create(field_class="kid", robots=[], seed=1, texture_seed=1)


def _dress(world: World, look: Look) -> World:
    """``world`` in ``look`` (textures, stripes, lights; the renderer made next shows it)."""
    apply_look(world.model, look)
    mujoco.mj_forward(world.model, world.data)
    return world


def test_frames_span_three_times_in_brightness_and_the_light_changes_colour(world: World) -> None:
    means, tints = {}, {}
    for seed in SEEDS:
        _dress(world, look_for(seed))
        with mujoco.Renderer(world.model, 60, 80) as renderer:
            frame = _robot_view(renderer, world).reshape(-1, 3).astype(float)
        means[seed] = frame.mean()
        tints[seed] = frame[:, 0].mean() / frame[:, 2].mean()  # red over blue
    assert max(means.values()) / min(means.values()) >= 3.0, means
    assert max(tints.values()) / min(tints.values()) > 1.2, tints
    # the light itself: the dawn's pink against the others' white and blue-white
    dawn = next(i for i, b in enumerate(BACKGROUNDS) if b.league_name == "kiara_1_dawn")
    pink = lighting(Look(0, 0, 0, dawn, 1.0)).diffuse[0]
    assert pink[0] > pink[1] * 1.5
    stadium = lighting(Look(0, 0, 0, 0, 1.0)).diffuse[0]
    assert stadium[2] >= stadium[0]


def test_luminosity_scales_the_lights_and_the_background(world: World) -> None:
    dim, bright = (lighting(Look(0, 0, 0, 0, lum)) for lum in (0.75, 1.25))
    assert bright.diffuse[0][1] / dim.diffuse[0][1] == pytest.approx(1.25 / 0.75)
    assert bright.ambient[1] / dim.ambient[1] == pytest.approx(1.25 / 0.75)
    frames = []
    for lum in (0.75, 1.25):
        _dress(world, Look(1, 0, 0, 0, lum))
        with mujoco.Renderer(world.model, 60, 80) as renderer:
            frames.append(_brightness(_robot_view(renderer, world)))
    assert frames[1] / frames[0] > 1.45  # the whole image, not a few per cent


def test_lines_are_textured_and_never_clip_to_white(world: World) -> None:
    texels = line_image().astype(float)
    assert texels.max() < 230 and texels[..., 1].std() > 4.0  # blades, not a flat white
    brightest = max(
        range(len(BACKGROUNDS)), key=lambda b: sum(lighting(Look(0, 0, 0, b, 1.0)).ambient)
    )
    _dress(world, Look(1, 0, 0, brightest, 1.25))
    line_geoms = {
        i for i in range(world.model.ngeom)
        if world.model.geom_matid[i] == world.model.material(LINE_TEXTURE).id
    }  # fmt: skip
    assert line_geoms
    with mujoco.Renderer(world.model, 120, 160) as renderer:
        camera = mujoco.MjvCamera()
        camera.lookat[:] = (0.0, 0.0, 0.0)  # the halfway line and the centre circle
        camera.distance, camera.azimuth, camera.elevation = 1.5, 90.0, -60.0
        renderer.update_scene(world.data, camera=camera)
        rgb = renderer.render().reshape(-1, 3)
        renderer.enable_segmentation_rendering()
        renderer.update_scene(world.data, camera=camera)
        ids = renderer.render()[..., 0].reshape(-1)
    on_line = np.isin(ids, list(line_geoms))
    assert on_line.mean() > 0.02
    white = (rgb.min(axis=1) >= 250)[on_line]
    assert white.mean() < 0.01, white.mean()


Frames = list[tuple[np.ndarray, np.ndarray]]


def _ball_frames(world: World, spots: list[tuple[float, float]]) -> Frames:
    """(frame, ball mask) with the ball at each of ``spots`` in front of a robot's eye."""
    ball = world.model.geom(BALL_GEOM).id
    out = []
    with mujoco.Renderer(world.model, 120, 160) as renderer:
        for x, y in spots:
            world.apply(PlaceBall(position=(x, y, 0.07), velocity=(0.0, 0.0, 0.0)))
            mujoco.mj_forward(world.model, world.data)
            rgb = _robot_view(renderer, world)
            renderer.enable_segmentation_rendering()
            mask = _robot_view(renderer, world)[..., 0] == ball
            renderer.disable_segmentation_rendering()
            out.append((rgb, mask))
    return out


def _hsv(rgb: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    f = rgb.astype(float) / 255.0
    v = f.max(axis=-1)
    s = np.where(v > 0, (v - f.min(axis=-1)) / np.maximum(v, 1e-9), 0.0)
    return v, s


def test_a_colour_ball_finder_tuned_on_one_look_loses_balls_on_the_others(world: World) -> None:
    """The finder of many teams: the ball's white panels are the pixels above a brightness and
    below a saturation, tuned on one look's balls; a ball is found when a quarter of its pixels
    pass. Tuned on the first look it finds every ball there, and misses balls elsewhere."""
    rng = np.random.default_rng(4)
    spots = [(float(rng.uniform(-0.9, 1.6)), float(rng.uniform(-0.6, 0.6))) for _ in range(8)]
    seeds = {}
    for seed in SEEDS:  # one texture seed per background
        seeds.setdefault(look_for(seed).background, seed)
    looks = {b: _ball_frames(_dress(world, look_for(s)), spots) for b, s in sorted(seeds.items())}
    tuned_on = min(looks)
    v_ball, s_ball = [], []
    for rgb, mask in looks[tuned_on]:
        v, s = _hsv(rgb)
        v_ball.append(v[mask])
        s_ball.append(s[mask])
    v_all, s_all = np.concatenate(v_ball), np.concatenate(s_ball)
    panels = v_all >= np.quantile(v_all, 0.5)
    v_min = float(np.quantile(v_all[panels], 0.1))
    s_max = float(np.quantile(s_all[panels], 0.9))

    def recall(frames: Frames) -> float:
        found = 0
        for rgb, mask in frames:
            v, s = _hsv(rgb)
            candidate = (v >= v_min) & (s <= s_max)
            found += int(mask.sum() > 0 and candidate[mask].mean() >= 0.25)
        return found / len(frames)

    recalls = {b: recall(frames) for b, frames in looks.items()}
    assert len(recalls) >= 5
    assert recalls[tuned_on] == 1.0, recalls
    assert min(recalls.values()) <= 0.5, recalls  # spread: the finder must be tuned per look


def test_the_look_changes_no_ground_truth(tmp_path: Path) -> None:
    """Two worlds that differ only in their texture seed move alike, to the bit, and record
    the same poses."""
    from simulator.recorder import Recorder
    from simulator.replay import load_replay

    poses = []
    for texture_seed in (3, 11):
        world = World.create(
            field_class="kid", robots=eight_robots()[:2], seed=5, texture_seed=texture_seed
        )
        assert look_for(3).background != look_for(11).background
        world.apply(PlaceBall(position=(-0.5, 0.2, 0.07), velocity=(1.5, 0.3, 0.0)))
        path = tmp_path / f"{texture_seed}.hlvsrec"
        with Recorder(path, world, match_id="m", rate_hz=25.0) as recorder:
            for _ in range(60):
                world.step()
                recorder.record(world, {"state": "PLAYING"})
        poses.append((world.data.qpos.copy(), [f.poses for f in load_replay(path).frames]))
    assert np.array_equal(poses[0][0], poses[1][0])
    assert all(np.array_equal(a, b) for a, b in zip(poses[0][1], poses[1][1], strict=True))


def test_the_cameras_know_the_software_renderers_the_gl_probe_knows() -> None:
    from simulator.gl import SOFTWARE_RENDERERS as PROBED
    from simulator.world.camera import SOFTWARE_RENDERERS

    assert SOFTWARE_RENDERERS == PROBED
