"""Replay format 2 (scene, chunks, index) and reading the version 1 files made before it."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import numpy as np
import pytest

from referee.snapshot import PlaceBall
from simulator.errors import ReplayError
from simulator.recorder import Recorder
from simulator.replay import ReplayFile, load_replay, scene_for
from simulator.replay.format import INDEX_MAGIC
from simulator.world import World
from tests.unit.world.conftest import eight_robots

V1_FIXTURE = Path(__file__).parent / "fixtures" / "v1-two-robots.hlvsrec"
V2_FIXTURE = Path(__file__).parent / "fixtures" / "v2-two-robots.hlvsrec"


def _record(path: Path, *, seconds: float, robots: int = 2, chunk_frames: int = 10) -> World:
    world = World.create(field_class="kid", robots=eight_robots()[:robots], seed=3)
    world.apply(PlaceBall(position=(0.0, 0.0, 0.07), velocity=(2.0, 0.5, 0.0)))
    with Recorder(path, world, match_id="m-v2", chunk_frames=chunk_frames) as recorder:
        for step in range(int(seconds * 125)):
            world.step()
            if step == 60:
                recorder.event({"type": "goal", "team": "blue", "sim_time_ms": world.sim_time_ms})
            recorder.record(world, {"state": "PLAYING", "secs_remaining": 600 - step // 125})
    return world


def test_version_2_is_indexed_and_seeks_to_a_chunk(tmp_path: Path) -> None:
    path = tmp_path / "m.hlvsrec"
    world = _record(path, seconds=2.0)
    assert path.read_bytes().endswith(INDEX_MAGIC)
    with ReplayFile(path) as replay:
        assert replay.indexed and replay.header.version == 3
        assert [c.frames for c in replay.chunks] == [10] * 5 + [1]
        assert replay.duration_ms == 2000 and replay.frame_count == 51
        assert replay.chunk_at(0) == 0 and replay.chunk_at(399) == 0 and replay.chunk_at(400) == 1
        assert replay.chunk_at(10_000) == 5
        assert replay.events == ({"type": "goal", "team": "blue", "sim_time_ms": 488,
                                  "frame_ms": 520},)  # fmt: skip
        block = replay.read_chunk(5)
        assert block.times_ms.tolist() == [2000]
        np.testing.assert_allclose(block.poses[0, :, :3], world.data.xpos, atol=6e-5)
        quat = block.poses[0, :, 3:]
        assert np.all(quat[:, 0] >= 0)  # stored with qw >= 0: the same turn as -q
        np.testing.assert_allclose(np.abs(np.sum(quat * world.data.xquat, axis=1)), 1, atol=1e-4)
        with pytest.raises(ReplayError, match="chunk 6 out of range"):
            replay.read_chunk(6)


def test_the_scene_travels_with_the_replay(tmp_path: Path) -> None:
    path = tmp_path / "m.hlvsrec"
    world = _record(path, seconds=0.1)
    header = load_replay(path).header
    scene = scene_for(header, str(path))
    assert scene is header.scene
    assert scene["bodies"] == list(header.body_names)
    names = [world.model.geom(i).name for i in range(world.model.ngeom)]
    # every geom but the robot cameras' meshes of the lines and cords (their boxes travel)
    assert [g["name"] for g in scene["geoms"]] == [n for n in names if not n.startswith("merged:")]
    assert sum(n.startswith("merged:") for n in names) == 3
    by_name = {g["name"]: g for g in scene["geoms"]}
    turf = by_name["turf"]
    assert turf["type"] == "plane" and turf["texture"] == "look:turf"
    assert turf["rgba"][1] > 0.4 > turf["rgba"][0]  # the turf's mean colour: green
    torso = by_name["red_1/torso:torso"]
    assert torso["type"] == "box" and torso["rgba"] == [0.85, 0.12, 0.1, 1.0]
    assert by_name["ball:geom"]["texture"] == "look:ball"
    assert scene["look"]["texture_seed"] == world.look.texture_seed
    assert scene["look"]["turf_colors"][0] != scene["look"]["turf_colors"][1]  # mowing stripes
    assert scene["robots"][0]["team"] == "red"
    assert scene["bodies"][scene["robots"][0]["root_body"]] == "red_1/torso"
    assert scene["field"]["half_length_m"] == 4.5
    assert [c["name"] for c in scene["cameras"]] == ["overview"]


def test_a_replay_whose_writer_died_is_read_up_to_its_last_chunk(tmp_path: Path) -> None:
    path = tmp_path / "m.hlvsrec"
    _record(path, seconds=2.0)
    blob = path.read_bytes()
    with ReplayFile(path) as whole:
        cut_at = whole.chunks[3].offset + 20
    cut = tmp_path / "cut.hlvsrec"
    cut.write_bytes(blob[:cut_at])
    with ReplayFile(cut) as replay:
        assert not replay.indexed
        assert [c.frames for c in replay.chunks] == [10, 10, 10]
        assert [e["type"] for e in replay.events] == ["goal"]
        assert replay.read_chunk(2).times_ms[-1] == 1160


def test_unknown_versions_and_corrupt_chunks_are_named(tmp_path: Path) -> None:
    path = tmp_path / "m.hlvsrec"
    _record(path, seconds=0.5)
    blob = bytearray(path.read_bytes())
    length = int.from_bytes(blob[8:12], "little")
    header = json.loads(blob[12 : 12 + length])
    future = tmp_path / "future.hlvsrec"
    bumped = json.dumps({**header, "version": 9}).encode()
    future.write_bytes(bytes(blob[:8]) + len(bumped).to_bytes(4, "little") + bumped
                       + bytes(blob[12 + length:]))  # fmt: skip
    with pytest.raises(ReplayError, match="format version 9; this reader knows versions 1, 2, 3"):
        ReplayFile(future)
    with ReplayFile(path) as replay:
        offset = replay.chunks[1].offset
    blob[offset + 200 : offset + 260] = bytes(60)
    broken = tmp_path / "broken.hlvsrec"
    broken.write_bytes(bytes(blob))
    with ReplayFile(broken) as replay, pytest.raises(ReplayError) as caught:
        replay.read_chunk(1)
    assert caught.value.path == str(broken) and "chunk 1" in caught.value.reason


def test_version_1_replays_are_still_read() -> None:
    with ReplayFile(V1_FIXTURE) as replay:
        header = replay.header
        assert header.version == 1 and header.scene is None and not replay.indexed
        assert header.match_id == "v1-fixture" and len(header.robots) == 2
        assert replay.frame_count == 13 and [c.frames for c in replay.chunks] == [13]
        assert [e["type"] for e in replay.events] == ["goal"]
        frames = list(replay.frames())
    assert frames[-1].sim_time_ms == 480 and frames[-1].game["score"] == {"red": 1, "blue": 0}
    assert frames[-1].poses.shape == (len(header.body_names), 7)
    scene = scene_for(header, str(V1_FIXTURE))  # today's models still have the same bodies
    assert scene["bodies"] == list(header.body_names)


def test_a_version_1_replay_of_changed_models_is_refused_with_a_reason(tmp_path: Path) -> None:
    blob = V1_FIXTURE.read_bytes()
    length = int.from_bytes(blob[8:12], "little")
    header = json.loads(blob[12 : 12 + length])
    header["body_names"] = header["body_names"][:-1]
    raw = json.dumps(header).encode()
    changed = tmp_path / "changed.hlvsrec"
    changed.write_bytes(blob[:8] + len(raw).to_bytes(4, "little") + raw + blob[12 + length :])
    with ReplayFile(changed) as replay, pytest.raises(ReplayError) as caught:
        scene_for(replay.header, str(changed))
    assert "47 bodies recorded" in caught.value.reason and caught.value.path == str(changed)


@pytest.mark.skipif(shutil.which("ffmpeg") is None, reason="needs ffmpeg")
def test_a_version_1_replay_still_renders(tmp_path: Path) -> None:
    from simulator.render import render_video

    video = render_video(V1_FIXTURE, tmp_path / "v1.mp4", width=160, height=90, fps=5)
    assert video.stat().st_size > 1000


def test_version_2_replays_are_still_read() -> None:
    """Version 2 (float32 poses) as its writer made it: 13 frames in chunks of 5."""
    with ReplayFile(V2_FIXTURE) as replay:
        assert replay.header.version == 2 and replay.indexed
        assert [c.frames for c in replay.chunks] == [5, 5, 3]
        assert replay.header.scene is not None
        assert scene_for(replay.header, "x") is replay.header.scene
        frames = list(replay.frames())
    assert [f.sim_time_ms for f in frames] == [40 * k for k in range(13)]
    assert frames[3].events == [{"sim_time_ms": 88, "team": "red", "type": "goal"}]
    assert frames[-1].poses.dtype == np.float32 and frames[-1].poses.shape == (48, 7)
    assert float(frames[-1].poses[1, 2]) == pytest.approx(0.07, abs=0.01)  # the ball, on the turf


def test_pose_coding_keeps_a_tenth_of_a_millimetre_and_the_turn() -> None:
    from simulator.replay.format import decode_poses, encode_poses

    rng = np.random.default_rng(4)
    poses = np.zeros((25, 30, 7))
    poses[:, :, :3] = rng.uniform(-7, 7, size=(25, 30, 3))
    quat = rng.normal(size=(25, 30, 4))
    poses[:, :, 3:] = quat / np.linalg.norm(quat, axis=2, keepdims=True)
    decoded = decode_poses(encode_poses(poses), 25, 30)
    np.testing.assert_allclose(decoded[:, :, :3], poses[:, :, :3], atol=5.01e-5)
    np.testing.assert_allclose(np.abs(np.sum(decoded[:, :, 3:] * poses[:, :, 3:], axis=2)), 1,
                               atol=1e-4)  # fmt: skip
