"""Replay files: round trip, bad files, and a video rendered from a replay."""

from __future__ import annotations

import json
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from referee.snapshot import PlaceBall
from simulator.errors import ReplayError
from simulator.recorder import Recorder
from simulator.render import caption
from simulator.replay import load_replay
from simulator.world import World
from tests.unit.world.conftest import eight_robots


def _record(path: Path, seconds: float, robots: int = 8) -> World:
    world = World.create(field_class="kid", robots=eight_robots()[:robots], seed=5)
    world.apply(PlaceBall(position=(0.0, 0.0, 0.07), velocity=(1.0, 2.0, 0.0)))
    with Recorder(path, world, match_id="m-42", rate_hz=25.0) as recorder:
        for step in range(int(seconds * 125)):
            world.step()
            if step == 10:
                recorder.event({"type": "goal", "team": "red", "sim_time_ms": world.sim_time_ms})
            game = {"state": "PLAYING", "score": {"red": 1, "blue": 0}}
            if robots == 8:
                game.update(half=1, secs_remaining=600 - world.sim_time_ms // 1000)
            recorder.record(world, game)
    return world


def test_recorder_round_trip(tmp_path: Path) -> None:
    path = tmp_path / "replay.hlvsrec"
    world = _record(path, seconds=1.0, robots=2)
    replay = load_replay(path)
    header = replay.header
    assert header.match_id == "m-42" and header.seed == 5 and header.rate_hz == 25.0
    assert header.field_class == "kid"
    assert [(p.team, p.number) for p in header.robots] == [
        (i.team.value, i.number) for i in world.robot_ids
    ]
    assert header.body_names[1] == world.model.body(1).name
    assert [f.sim_time_ms for f in replay.frames] == [40 * k for k in range(26)]
    assert replay.frames[0].game == {} and replay.frames[0].events == []
    assert replay.frames[3].events == [{"sim_time_ms": 88, "team": "red", "type": "goal"}]
    assert replay.frames[-1].game == {"score": {"blue": 0, "red": 1}, "state": "PLAYING"}
    last = replay.frames[-1].poses
    assert last.dtype == np.float32 and last.shape == (world.model.nbody, 7)
    np.testing.assert_allclose(last[:, :3], world.data.xpos, atol=6e-5)  # 0.1 mm steps
    same_turn = np.abs(np.sum(last[:, 3:] * world.data.xquat, axis=1))  # q and -q
    np.testing.assert_allclose(same_turn, 1.0, atol=1e-4)


def test_bad_replays_name_the_file(tmp_path: Path) -> None:
    bad = tmp_path / "bad.hlvsrec"
    bad.write_bytes(b"not a replay")
    with pytest.raises(ReplayError) as caught:
        load_replay(bad)
    assert caught.value.path == str(bad) and "magic" in caught.value.reason
    good = tmp_path / "good.hlvsrec"
    _record(good, seconds=0.2, robots=1)
    truncated = tmp_path / "truncated.hlvsrec"
    truncated.write_bytes(good.read_bytes()[:40])
    with pytest.raises(ReplayError, match="truncated"):
        load_replay(truncated)
    header_len = int.from_bytes(good.read_bytes()[8:12], "little")
    header = json.loads(good.read_bytes()[12 : 12 + header_len])
    assert header["version"] == 3


@pytest.mark.skipif(shutil.which("ffprobe") is None, reason="needs ffmpeg")
def test_ten_second_video_of_eight_robots(tmp_path: Path) -> None:
    replay = tmp_path / "match.hlvsrec"
    _record(replay, seconds=10.0)
    video = tmp_path / "match.mp4"
    done = subprocess.run(
        [sys.executable, "-m", "simulator", "render", str(replay), "-o", str(video),
         "--width", "320", "--height", "180", "--fps", "10"],
        capture_output=True, text=True, timeout=300,
    )  # fmt: skip
    assert done.returncode == 0, done.stderr
    probe = subprocess.run(
        ["ffprobe", "-v", "error", "-show_entries",
         "stream=codec_type,width,height,codec_name,pix_fmt:format=duration", "-of", "json",
         str(video)],
        capture_output=True, text=True, check=True,
    )  # fmt: skip
    info = json.loads(probe.stdout)
    stream = info["streams"][0]
    assert [s["codec_type"] for s in info["streams"]] == ["video", "subtitle"]
    assert (stream["width"], stream["height"]) == (320, 180)
    assert stream["codec_name"] == "h264" and stream["pix_fmt"] == "yuv420p"
    assert float(info["format"]["duration"]) == pytest.approx(10.0, abs=0.3)


def test_captions_follow_the_game_state() -> None:
    game = {"state": "PLAYING", "half": 2, "secs_remaining": 125.4, "score": {"red": 2, "blue": 3}}
    assert caption(game) == "PLAYING  2nd half  02:05  red 2 : 3 blue"
    assert caption({}) == ""


def test_render_cli_rejects_a_bad_replay(tmp_path: Path) -> None:
    bad = tmp_path / "bad.hlvsrec"
    bad.write_bytes(b"garbage")
    done = subprocess.run(
        [sys.executable, "-m", "simulator", "render", str(bad), "-o", str(tmp_path / "x.mp4")],
        capture_output=True, text=True, timeout=60,
    )  # fmt: skip
    assert done.returncode == 2
    assert str(bad) in done.stderr and "Traceback" not in done.stderr
