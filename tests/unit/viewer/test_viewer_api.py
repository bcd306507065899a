"""The viewer API over HTTP (in-process app): meta, chunks, stats, sources, live stream."""

from __future__ import annotations

import json
import shutil
import struct
import threading
from collections.abc import Iterator
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from fastapi.testclient import TestClient

from orchestrator.config import load_game, to_match_spec
from simulator.replay import ReplayFile
from tests.unit.config.conftest import EXAMPLES
from tests.unit.viewer.replays import GOAL_MS, record_match
from viewer import Catalog, SourceError
from viewer.api import create_app
from viewer.live import Callback

V1_FIXTURE = Path(__file__).parents[1] / "replay" / "fixtures" / "v1-two-robots.hlvsrec"


@pytest.fixture(scope="module")
def match_dir(tmp_path_factory: pytest.TempPathFactory) -> Path:
    folder = tmp_path_factory.mktemp("viewer") / "match-7"
    record_match(folder)
    return folder


def _client(*paths: Path) -> tuple[TestClient, list[str]]:
    catalog = Catalog()
    pages = [page for path in paths for page in catalog.add_path(path)]
    return TestClient(create_app(catalog)), pages


def test_meta_and_chunks_carry_the_replay(match_dir: Path) -> None:
    client, pages = _client(match_dir)
    assert pages == ["/watch/replay/match-7"]
    meta = client.get("/api/viewer/replays/match-7/meta").json()
    assert meta["match_id"] == "viewer-test" and meta["version"] == 3 and meta["has_stats"]
    assert meta["duration_ms"] == 3000 and meta["chunks"][1] == [1000, 1960, 25]
    assert [(e["type"], e["frame_ms"]) for e in meta["events"]] == [("goal", GOAL_MS)]
    assert len(meta["scene"]["geoms"]) > 200 and meta["body_count"] == len(meta["scene"]["bodies"])
    blob = client.get("/api/viewer/replays/match-7/chunks/2").content
    (length,) = struct.unpack_from("<I", blob)
    head = json.loads(blob[4 : 4 + length])
    start = 4 + length + (-length % 4)
    poses = np.frombuffer(blob[start:], dtype="<f4").reshape(25, meta["body_count"], 7)
    with ReplayFile(match_dir / "public" / "replay.hlvsrec") as replay:
        block = replay.read_chunk(2)
    assert head["times"] == block.times_ms.tolist() and head["games"] == block.games
    np.testing.assert_array_equal(poses, block.poses)
    assert head["games"][0]["score"] == {"red": 0, "blue": 0}
    assert head["games"][-1]["score"] == {"red": 1, "blue": 0}
    stats = client.get("/api/viewer/replays/match-7/stats").json()
    assert [s["real_time_factor"] for s in stats] == [1.0, 1.1, 1.2, 1.3]


def test_pages_and_static_files_are_served(match_dir: Path) -> None:
    client, _ = _client(match_dir)
    page = client.get("/watch/replay/match-7")
    assert page.status_code == 200
    assert '<script type="module" src="/watch/static/app.js">' in page.text
    script = client.get("/watch/static/app.js")
    assert script.status_code == 200 and "javascript" in script.headers["content-type"]
    assert len(script.content) > 100_000  # three.js is bundled: no page needs the internet
    assert "https://" not in page.text


def test_unknown_ids_and_chunks_are_named(match_dir: Path) -> None:
    client, _ = _client(match_dir)
    missing = client.get("/api/viewer/replays/match-8/meta")
    assert missing.status_code == 404 and "match-8" in missing.text and "match-7" in missing.text
    far = client.get("/api/viewer/replays/match-7/chunks/99")
    assert far.status_code == 404 and "out of range 0..3" in far.text


def test_version_1_replays_are_served_with_a_rebuilt_scene() -> None:
    client, pages = _client(V1_FIXTURE)
    assert pages == ["/watch/replay/v1-two-robots"]
    meta = client.get("/api/viewer/replays/v1-two-robots/meta").json()
    assert meta["version"] == 1 and meta["scene"]["bodies"][2] == "red_1/torso"
    assert len(client.get("/api/viewer/replays/v1-two-robots/chunks/0").content) > 13 * 48 * 28


def test_paths_without_replays_are_refused(tmp_path: Path) -> None:
    with pytest.raises(SourceError, match="no replay in this folder"):
        Catalog().add_path(tmp_path)
    other = tmp_path / "notes.txt"
    other.write_text("x")
    with pytest.raises(SourceError, match="not a replay"):
        Catalog().add_path(other)
    with pytest.raises(SourceError, match="no such file"):
        Catalog().add_path(tmp_path / "absent")


def test_a_running_match_with_a_broken_spec_is_refused_naming_the_field(tmp_path: Path) -> None:
    spec_path = tmp_path / "running" / "simulator" / "match_spec.json"
    spec_path.parent.mkdir(parents=True)
    spec_path.write_text(json.dumps({"match_id": "m 1",
                                     "network": {"telemetry_listen": "tcp/10.0.0.2:7447"}}))
    with pytest.raises(SourceError, match=r"unreadable match spec: .*: /(seed|red|blue|game_type)"):
        Catalog().add_path(tmp_path / "running")


class _FakeFeed:
    """Stands in for the zenoh subscription: pushes canned telemetry from a thread."""

    def __init__(self, endpoint: str, match_id: str, callback: Callback) -> None:
        self.endpoint = endpoint
        poses = struct.pack("<I", 1234) + np.arange(14, dtype="<f4").tobytes()
        messages = [("scene", b'{"scene": {}}'), ("state", b'{"sim_time_ms": 1234}'),
                    ("poses", poses), ("events", b'{"type": "goal"}')]  # fmt: skip
        self._thread = threading.Thread(target=lambda: [callback(*m) for m in messages])
        self._thread.start()

    def close(self) -> None:
        self._thread.join()


def test_the_live_stream_relays_telemetry_as_server_sent_events(tmp_path: Path) -> None:
    folder = tmp_path / "running"
    (folder / "simulator").mkdir(parents=True)
    spec = to_match_spec(load_game(EXAMPLES / "scrimmage_1v1" / "game.json"),
                         robot_addresses={}, telemetry_listen="tcp/10.0.0.2:7447")
    replace(spec, match_id="m 1").write(folder / "simulator" / "match_spec.json")
    catalog = Catalog()
    assert catalog.add_path(folder) == ["/watch/live/m-1"]
    client = TestClient(create_app(catalog, feed_factory=_FakeFeed))
    events: list[tuple[str, str]] = []
    with client.stream("GET", "/api/viewer/live/m-1/stream") as response:
        kind = ""
        lines: Iterator[str] = response.iter_lines()
        for line in lines:
            if line.startswith("event: "):
                kind = line[7:]
            elif line.startswith("data: "):
                events.append((kind, line[6:]))
                if len(events) == 5:
                    break
    assert [k for k, _ in events] == ["teams", "scene", "state", "poses", "event"]
    assert json.loads(events[0][1]) == {"red": spec.red.name, "blue": spec.blue.name}
    assert events[2][1] == '{"sim_time_ms": 1234}'
    import base64

    raw = base64.b64decode(events[3][1])
    assert struct.unpack_from("<I", raw)[0] == 1234 and len(raw) == 4 + 14 * 4


def test_meta_and_index_name_the_teams_of_a_match_folder(tmp_path: Path) -> None:
    folder = tmp_path / "named"
    record_match(folder, seconds=1.0)
    spec = to_match_spec(load_game(EXAMPLES / "scrimmage_1v1" / "game.json"), robot_addresses={},
                         telemetry_listen="")
    spec = replace(spec, red=replace(spec.red, name="Ants"), blue=replace(spec.blue, name="Bees"))
    spec.write(folder / "simulator" / "match_spec.json")
    bare = tmp_path / "bare"
    record_match(bare, seconds=1.0)
    client, pages = _client(folder, bare / "public" / "replay.hlvsrec")
    assert pages == ["/watch/replay/named", "/watch/replay/bare"]
    teams = {"red": "Ants", "blue": "Bees"}
    named = client.get("/api/viewer/replays/named/meta").json()
    assert named["teams"] == teams and named["complete"] is True  # closed by its recorder
    assert client.get("/api/viewer/replays/bare/meta").json()["teams"] is None
    listing = client.get("/api/viewer/index").json()["replays"]
    assert [(r["id"], r["teams"]) for r in listing] == [("named", teams), ("bare", None)]


def test_a_live_match_s_replay_follows_its_file_to_the_public_copy(tmp_path: Path) -> None:
    """Asked for while the match runs, the replay is the one being written; once the match's
    output is collected (that file gone, the public copy there) it is the public copy."""
    folder = tmp_path / "running"
    recorded = record_match(tmp_path / "recorded", seconds=1.0)
    out = folder / "simulator" / "out"
    out.mkdir(parents=True)
    shutil.copy(recorded, out / "replay.hlvsrec")
    spec = to_match_spec(load_game(EXAMPLES / "scrimmage_1v1" / "game.json"),
                         robot_addresses={}, telemetry_listen="tcp/10.0.0.2:7447")
    replace(spec, match_id="m2").write(folder / "simulator" / "match_spec.json")
    client, pages = _client(folder)
    assert "/watch/live/m2" in pages
    assert client.get("/api/viewer/replays/m2/meta").status_code == 200
    (folder / "public").mkdir()
    (out / "replay.hlvsrec").replace(folder / "public" / "replay.hlvsrec")
    meta = client.get("/api/viewer/replays/m2/meta")
    assert meta.status_code == 200 and meta.json()["complete"] is True


def test_a_replay_its_writer_left_open_is_not_complete(tmp_path: Path) -> None:
    path = record_match(tmp_path / "open", seconds=1.0)
    path.write_bytes(path.read_bytes()[:-40])  # no index, no trailer: the recorder died
    client, _ = _client(path)
    meta = client.get("/api/viewer/replays/open/meta").json()
    assert meta["complete"] is False and meta["duration_ms"] > 0


def test_hlvs_view_names_a_path_without_a_replay(tmp_path: Path) -> None:
    import subprocess
    import sys

    done = subprocess.run(
        [sys.executable, "-m", "hlvs", "view", str(tmp_path / "nowhere")],
        capture_output=True, text=True, timeout=120,
    )  # fmt: skip
    assert done.returncode == 2
    assert f"{tmp_path / 'nowhere'}: no such file or folder" in done.stderr
    assert "Traceback" not in done.stderr and done.stdout == ""
