"""The league's look: the same texture seed renders the same images, another seed others; the
ball carries its pattern; the replay, the video and the robot camera frames show the same look."""

from __future__ import annotations

from pathlib import Path

import mujoco
import numpy as np
import pytest

from referee.snapshot import PlaceBall
from simulator.world import CameraRenderer, World
from simulator.world.camera_model import CameraModel
from simulator.world.look import BACKGROUNDS, BALLS, TURFS, look_for

from .conftest import RED_1, eight_robots


def _camera_image(texture_seed: int, *, camera: CameraModel | None = None) -> np.ndarray:
    world = World.create(
        field_class="kid", robots=eight_robots()[:1], seed=1, texture_seed=texture_seed,
        camera_model=camera,
    )  # fmt: skip
    world.apply(PlaceBall(position=(-0.4, -1.5, 0.07), velocity=(0.0, 0.0, 0.0)))
    world.step()
    with CameraRenderer(world, 160, 120) as renderer:
        raw = renderer.render(RED_1, sim_time_ms=world.sim_time_ms)
    return np.frombuffer(raw, np.uint8).reshape(120, 160, 3)


def test_same_seed_same_image_other_seed_other_image() -> None:
    league = CameraModel.league(5)
    first = _camera_image(21, camera=league)
    assert np.array_equal(first, _camera_image(21, camera=league))
    assert look_for(24).background != look_for(21).background  # another stadium around
    other = _camera_image(24, camera=league)
    assert np.abs(first.astype(int) - other.astype(int)).mean() > 5.0


def test_the_seed_picks_every_variant() -> None:
    looks = [look_for(seed) for seed in range(200)]
    assert {look.turf for look in looks} == set(range(len(TURFS)))
    assert {look.ball for look in looks} == set(range(len(BALLS)))
    assert {look.background for look in looks} == set(range(len(BACKGROUNDS)))
    assert all(0.75 <= look.luminosity <= 1.25 for look in looks)


def test_the_five_ball_families_show_their_designs_lit_and_shaded() -> None:
    from simulator.world.look import Look, apply_look, ball_image

    images = [ball_image(v).astype(int) for v in range(len(BALLS))]
    assert len({b.family for b in BALLS}) == 5
    for v, image in enumerate(images):
        texels = image.reshape(-1, 3)
        dark = (texels.max(axis=1) < 90).mean()
        light = (texels.min(axis=1) > 180).mean()
        assert 0.03 < dark < 0.6 and light > 0.3, (BALLS[v].name, dark, light)
        for other in images[:v]:
            assert np.abs(image - other).mean() > 10.0  # five designs, not recolourings
    world = World.create(field_class="kid", robots=[], seed=1, texture_seed=1)
    for v in range(len(BALLS)):
        apply_look(world.model, Look(1, 0, v, 0, 1.0))
        mujoco.mj_forward(world.model, world.data)
        with mujoco.Renderer(world.model, 120, 120) as renderer:
            camera = mujoco.MjvCamera()
            camera.lookat[:] = (0.0, 0.0, 0.07)
            camera.distance, camera.elevation, camera.azimuth = 0.3, 0.0, 40.0
            renderer.update_scene(world.data, camera=camera)
            image = renderer.render().astype(float)
        top, bottom = image[30:50, 45:75].mean(), image[70:90, 45:75].mean()
        assert top > 1.15 * bottom, (BALLS[v].name, top, bottom)  # lit from above, shaded below
        assert image[30:90, 30:90].max() < 255  # a 0.8 white, not a painted 1.0


def test_turf_has_mowing_stripes_and_blades() -> None:
    from simulator.world.look import turf_image

    turf = turf_image(0).astype(float)
    half = turf.shape[1] // 2
    light, dark = turf[:, :half, 1].mean(), turf[:, half:, 1].mean()
    assert light > dark * 1.05  # two stripes
    assert turf[:, :half, 1].std() > 8.0  # blade texture, not a flat colour
    # green, never as dark as the ball's patches nor as white as the lines
    assert turf[..., 1].min() > 75 and turf[..., 0].max() < 150


def test_mowing_stripes_on_the_rendered_field_are_as_wide_as_the_look_says() -> None:
    """A tile of the turf texture holds two stripes, and MuJoCo's renderer lays a plane's tile
    over 2 / texrepeat metres: seen from straight above, between the centre circle and the
    penalty area where no line is, the stripes are ``stripe_m`` wide (they were twice that)."""
    from simulator.world.look import Look, apply_look

    world = World.create(field_class="kid", robots=[], seed=1, texture_seed=1)
    size, distance = 240, 1.5
    metres_per_px = 2 * distance * np.tan(np.radians(world.model.vis.global_.fovy / 2)) / size
    for turf in (0, 1):
        apply_look(world.model, Look(1, turf, 0, 0, 1.0))
        mujoco.mj_forward(world.model, world.data)
        with mujoco.Renderer(world.model, size, size) as renderer:
            camera = mujoco.MjvCamera()
            camera.lookat[:] = (-1.25, 1.5, 0.0)  # x -1.87..-0.63, y 0.88..2.12: no line
            camera.distance, camera.elevation, camera.azimuth = distance, -90.0, 90.0
            renderer.update_scene(world.data, camera=camera)
            green = renderer.render()[..., 1].astype(float)
        profile = np.convolve(green.mean(axis=0), np.ones(15) / 15, mode="valid")
        light = profile > (profile.max() + profile.min()) / 2
        edges = np.flatnonzero(np.diff(light.astype(int))) * metres_per_px
        assert len(edges) >= 2, (turf, edges)
        assert np.diff(edges)[0] == pytest.approx(TURFS[turf].stripe_m, rel=0.1), (turf, edges)


def test_the_ideal_camera_has_no_noise_and_the_league_camera_has() -> None:
    ideal = _camera_image(21, camera=CameraModel.ideal()).astype(int)
    noisy = _camera_image(
        21, camera=CameraModel(seed=2, exposure_gain=1.0, auto_exposure=0.0, noise_std=3.0)
    )
    diff = noisy.astype(int) - ideal
    assert diff.std() == pytest.approx(3.0, rel=0.2)
    assert abs(diff.mean()) < 0.5


def test_the_luminosity_is_in_the_image_unless_the_camera_declares_auto_exposure() -> None:
    """The look's luminosity lights the scene (no hidden compensation); a camera model with
    auto-exposure evens out its declared share of it, on top of its own exposure gain."""
    ideal = _camera_image(21, camera=CameraModel.ideal()).astype(float)
    model = CameraModel(exposure_gain=1.1, auto_exposure=0.8, noise_std=0.0)
    assert model.gain(look_for(21).luminosity) == pytest.approx(
        1.1 * look_for(21).luminosity ** -0.8
    )
    assert CameraModel.league(5).auto_exposure == 0.0
    assert CameraModel.league(5).gain(1.25) == CameraModel.league(5).gain(0.75)
    corrected = _camera_image(21, camera=model).astype(float)
    gain = model.gain(look_for(21).luminosity)
    unclipped = ideal * gain < 250
    # the gain is applied in 1/64 steps, the result rounded down
    assert np.abs(corrected[unclipped] - ideal[unclipped] * gain).max() <= 2.5


def test_camera_frames_and_video_scene_from_a_replay(tmp_path: Path) -> None:
    from simulator.camera_frames import render_camera_frames
    from simulator.recorder import Recorder
    from simulator.replay import load_replay, scene_for
    from simulator.scene_model import scene_model

    world = World.create(
        field_class="kid", robots=eight_robots()[:2], seed=1, texture_seed=8,
        camera_model=CameraModel.league(1),
    )  # fmt: skip
    path = tmp_path / "replay.hlvsrec"
    with Recorder(path, world, match_id="m", rate_hz=25.0) as recorder:
        for _ in range(20):
            world.step()
            recorder.record(world, {"state": "PLAYING"})
    scene = scene_for(load_replay(path).header, str(path))
    model = scene_model(scene)
    for name in ("look:turf", "look:ball", "look:sky"):  # the video's textures: the world's
        ours, theirs = model.texture(name), world.model.texture(name)
        assert np.array_equal(
            model.tex_data[ours.adr[0] : ours.adr[0] + 3 * ours.width[0] * ours.height[0]],
            world.model.tex_data[
                theirs.adr[0] : theirs.adr[0] + 3 * theirs.width[0] * theirs.height[0]
            ],
        )
    files = render_camera_frames(path, tmp_path / "frames", robot="red-1", fps=10.0)
    assert [f.name for f in files] == ["red-1_00000.png", "red-1_00001.png"]
    assert files[0].read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    with pytest.raises(Exception, match="no head camera of robot 'blue-9'"):
        render_camera_frames(path, tmp_path / "x", robot="blue-9")
