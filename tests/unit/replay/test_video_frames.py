"""The match video's frames: the boxes drawn one quad a face and the turf in 1 m cells
(``video_surfaces``), read from OpenGL as R,G,B,A rows bottom up and turned upright by ffmpeg."""

from __future__ import annotations

import shutil
import subprocess
from pathlib import Path

import mujoco
import numpy as np
import pytest

from referee.snapshot import PlaceBall
from simulator.recorder import Recorder
from simulator.render import render_video, video_surfaces
from simulator.replay import Replay, load_replay, scene_for
from simulator.scene_model import Placer, frames_for, scene_model
from simulator.world import World
from simulator.world.camera import reads_frames
from simulator.world.camera_scene import PLANE_GRID_M
from tests.unit.world.conftest import eight_robots


@pytest.fixture(scope="module")
def replay_path(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """Half a second of four robots and a rolling ball."""
    path = tmp_path_factory.mktemp("video") / "replay.hlvsrec"
    world = World.create(field_class="kid", robots=eight_robots()[:4], seed=3)
    world.apply(PlaceBall(position=(0.5, 0.3, 0.07), velocity=(1.0, 0.5, 0.0)))
    with Recorder(path, world, match_id="m-video", rate_hz=25.0) as recorder:
        for _ in range(63):
            world.step()
            recorder.record(world, {"state": "PLAYING", "score": {"red": 0, "blue": 0}})
    return path


def _frame(replay: Replay, path: Path, index: int, *, surfaces: bool, size: tuple[int, int]):
    """The replay's frame ``index`` from the overview camera as ``mujoco.Renderer.render``
    gives it (R,G,B rows top down), with or without :func:`video_surfaces`, and the model."""
    model = scene_model(scene_for(replay.header, str(path)))
    if surfaces:
        video_surfaces(model)
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)  # the lights' directions, as the video has them
    Placer(model, data)(replay.frames[index].poses.astype(np.float64))
    renderer = mujoco.Renderer(model, height=size[1], width=size[0])
    renderer.scene.flags[mujoco.mjtRndFlag.mjRND_SHADOW] = False
    option = mujoco.MjvOption()
    option.geomgroup[4] = 0
    try:
        renderer.update_scene(data, camera="overview", scene_option=option)
        return renderer.render().copy(), model, renderer
    except BaseException:
        renderer.close()
        raise


def test_video_surfaces_draw_boxes_in_one_quad_a_face_and_the_turf_in_metre_cells(
    replay_path: Path,
) -> None:
    replay = load_replay(replay_path)
    own, own_model, own_renderer = _frame(replay, replay_path, 5, surfaces=False, size=(640, 360))
    own_renderer.close()
    coarse, model, renderer = _frame(replay, replay_path, 5, surfaces=True, size=(640, 360))
    renderer.close()
    assert own_model.vis.quality.numquads == 4 and model.vis.quality.numquads == 1
    planes = model.geom_type == mujoco.mjtGeom.mjGEOM_PLANE
    assert own_model.geom_size[planes, 2].max() < PLANE_GRID_M
    assert np.all(model.geom_size[planes, 2] >= PLANE_GRID_M)
    np.testing.assert_array_equal(model.geom_size[~planes], own_model.geom_size[~planes])
    # the same picture: the odd pixel of a net's cord, thinner than a pixel, rasterised apart
    diff = np.abs(own.astype(int) - coarse.astype(int)).max(axis=2)
    assert np.count_nonzero(diff) > 0  # the turf's cells did change what was drawn
    assert np.mean(diff > 8) < 0.002 and diff.mean() < 0.1


def test_the_rgba_read_is_the_renderers_frame_bottom_up(replay_path: Path) -> None:
    replay = load_replay(replay_path)
    expected, _, renderer = _frame(replay, replay_path, 7, surfaces=True, size=(320, 180))
    try:
        read = reads_frames(renderer, "RGBA")
        assert read is not None  # OSMesa, no multisampling: the fast way
        rgba = np.empty((180, 320, 4), dtype=np.uint8)
        got = read(rgba)
        assert got is rgba
        np.testing.assert_array_equal(got[::-1, :, :3], expected)
    finally:
        renderer.close()


@pytest.mark.skipif(shutil.which("ffmpeg") is None, reason="needs ffmpeg")
def test_the_video_is_upright(replay_path: Path, tmp_path: Path) -> None:
    """The video's first frame against the renderer's own (R,G,B top down): ffmpeg turned the
    rows and dropped the alpha."""
    video = render_video(replay_path, tmp_path / "m.mp4", width=320, height=180, fps=5)
    raw = subprocess.run(
        ["ffmpeg", "-loglevel", "error", "-i", str(video), "-frames:v", "1", "-f", "rawvideo",
         "-pix_fmt", "rgb24", "-"],
        capture_output=True, check=True, timeout=60,
    ).stdout  # fmt: skip
    decoded = np.frombuffer(raw, dtype=np.uint8).reshape(180, 320, 3).astype(int)
    replay = load_replay(replay_path)
    first = next(iter(frames_for(replay, 5.0)))
    expected, _, renderer = _frame(replay, replay_path, first, surfaces=True, size=(320, 180))
    renderer.close()
    upright = np.abs(decoded - expected.astype(int)).mean()
    upside_down = np.abs(decoded - expected[::-1].astype(int)).mean()
    assert upright < 6.0, upright  # x264 and 4:2:0 colour lose a little
    assert upside_down > 3 * upright, (upright, upside_down)


@pytest.mark.skipif(shutil.which("ffmpeg") is None, reason="needs ffmpeg")
def test_ffmpeg_failing_is_an_error_naming_the_output(replay_path: Path, tmp_path: Path) -> None:
    """ffmpeg cannot write the video (a folder is where it was to be): the frames stop and its
    message is the error's reason; nothing waits on a pipe nobody reads."""
    from simulator.errors import RenderError

    output = tmp_path / "m.mp4"
    output.mkdir()
    with pytest.raises(RenderError) as caught:
        render_video(replay_path, output, width=320, height=180, fps=25)
    assert caught.value.output == str(output)
    assert "ffmpeg exited" in caught.value.reason and "m.mp4" in caught.value.reason
    assert not (tmp_path / "m.mp4.srt").exists()
