"""``hlvs export``: MCAP with Foxglove schemas, read back with the mcap reader."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest
from foxglove_schemas_protobuf.FrameTransforms_pb2 import FrameTransforms
from foxglove_schemas_protobuf.SceneUpdate_pb2 import SceneUpdate
from mcap.reader import make_reader

from simulator.replay import ReplayFile
from tests.unit.viewer.replays import GOAL_MS, record_match


@pytest.fixture(scope="module")
def replay(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return record_match(tmp_path_factory.mktemp("mcap") / "match")


def test_export_writes_foxglove_channels_in_simulated_time(replay: Path, tmp_path: Path) -> None:
    output = tmp_path / "match.mcap"
    done = subprocess.run(
        [sys.executable, "-m", "hlvs", "export", str(replay), "-o", str(output)],
        capture_output=True, text=True, timeout=120,
    )  # fmt: skip
    assert done.returncode == 0, done.stderr
    assert " messages on 5 channels, 3.0 s of simulated time" in done.stdout
    with output.open("rb") as stream:
        reader = make_reader(stream)
        summary = reader.get_summary()
        assert summary is not None
        topics = {c.topic: summary.schemas[c.schema_id].name for c in summary.channels.values()}
        assert topics == {
            "/scene": "foxglove.SceneUpdate", "/tf": "foxglove.FrameTransforms",
            "/game_state": "game_state", "/referee/events": "referee/events",
            "/robots/red-1/api": "robots/red-1/api",
        }  # fmt: skip
        messages = {topic: [] for topic in topics}  # type: ignore[var-annotated]
        for _, channel, message in reader.iter_messages():
            messages[channel.topic].append(message)
    with ReplayFile(replay) as recorded:
        frames = list(recorded.frames())
        names = recorded.header.body_names
    assert len(messages["/tf"]) == len(frames) == 76
    k = 50
    tf = FrameTransforms.FromString(messages["/tf"][k].data)
    assert messages["/tf"][k].log_time == frames[k].sim_time_ms * 1_000_000
    ball = next(t for t in tf.transforms if t.child_frame_id == "ball")
    assert ball.parent_frame_id == "world"
    index = names.index("ball")
    assert ball.translation.x == pytest.approx(float(frames[k].poses[index, 0]), abs=1e-6)
    assert ball.rotation.w == pytest.approx(float(frames[k].poses[index, 3]), abs=1e-6)
    assert len(tf.transforms) == len(names) - 1
    scene = SceneUpdate.FromString(messages["/scene"][0].data)
    entities = {e.id: e for e in scene.entities}
    assert entities["ball"].spheres and entities["red_1/torso"].frame_locked
    torso = entities["red_1/torso"].cubes[0]
    assert (torso.color.r, torso.color.b) == pytest.approx((0.85, 0.1))
    goal = json.loads(messages["/referee/events"][0].data)
    assert goal["type"] == "goal" and messages["/referee/events"][0].log_time == GOAL_MS * 10**6
    states = [json.loads(m.data) for m in messages["/game_state"]]
    assert states[0] == {} and states[-1]["score"] == {"red": 1, "blue": 0}
    api = [json.loads(m.data) for m in messages["/robots/red-1/api"]]
    assert [a["round_trip_ms"] for a in api] == [2.0, 3.0, 4.0, 5.0]


def test_export_of_a_bad_replay_names_the_file(tmp_path: Path) -> None:
    bad = tmp_path / "bad.hlvsrec"
    bad.write_bytes(b"nothing")
    done = subprocess.run(
        [sys.executable, "-m", "hlvs", "export", str(bad), "-o", str(tmp_path / "x.mcap")],
        capture_output=True, text=True, timeout=120,
    )  # fmt: skip
    assert done.returncode == 2
    assert str(bad) in done.stderr and "bad magic" in done.stderr and "Traceback" not in done.stderr
