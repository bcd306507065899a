"""Fault: the match's disk fills while the simulator records the replay (a real file system: a
small tmpfs of the test's own, nearly filled).

Outcome: the match goes on (before, the write's ``OSError`` ended the match loop as an internal
error, and closing the recorder raised it again, so the simulator died without its results);
the replay keeps every whole chunk written before the disk filled and still loads (a reader
scans a file without an index); the recorder's ``cut`` names the file, the error and the
simulated time from which the replay is missing, and the simulator's log says so. The loss is
the replay's tail, named."""

from __future__ import annotations

import contextlib
import json
import logging
import os
import subprocess
import threading
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

from referee.snapshot import PlaceBall
from simulator.errors import ReplayError
from simulator.recorder import Recorder
from simulator.replay import load_replay
from simulator.world import World
from tests.unit.world.conftest import eight_robots

pytestmark = [pytest.mark.root, pytest.mark.slow,
              pytest.mark.skipif(os.geteuid() != 0, reason="mounts a tmpfs")]


def _nearly_full(mount: Path, left_bytes: int) -> Path:
    """A 4 MiB tmpfs mounted at ``mount`` with about ``left_bytes`` left."""
    mount.mkdir()
    subprocess.run(["mount", "-t", "tmpfs", "-o", "size=4m", "tmpfs", str(mount)], check=True)
    free = os.statvfs(mount).f_bavail * os.statvfs(mount).f_frsize
    (mount / "filler").write_bytes(b"\0" * (free - left_bytes))
    return mount


def _header_bytes(world: World) -> int:
    from simulator.recorder import replay_header
    from simulator.replay.format import dumps

    return len(dumps(replay_header(world, match_id="full", rate_hz=25.0, chunk_frames=25)))


def _two_robots() -> World:
    world = World.create(field_class="kid", robots=eight_robots()[:2], seed=5)
    world.apply(PlaceBall(position=(0.0, 0.0, 0.07), velocity=(1.0, 2.0, 0.0)))
    return world


@pytest.fixture
def full_disk(tmp_path: Path) -> Iterator[Path]:
    """Room for the replay's header (its scene: tens of KiB) and about 16 KiB more."""
    try:
        yield _nearly_full(tmp_path / "disk", _header_bytes(_two_robots()) + 16 * 1024)
    finally:
        subprocess.run(["umount", "--lazy", str(tmp_path / "disk")], check=True)


@pytest.fixture
def filling_disk(tmp_path: Path) -> Iterator[Path]:
    """Room for the simulator's reserve for its results and about 1 MiB more."""
    from contracts.files import RESERVE_BYTES

    try:
        yield _nearly_full(tmp_path / "disk", RESERVE_BYTES + 1024 * 1024)
    finally:
        subprocess.run(["umount", "--lazy", str(tmp_path / "disk")], check=True)


def test_a_full_disk_cuts_the_replay_never_the_match(
        full_disk: Path, caplog: pytest.LogCaptureFixture) -> None:
    path = full_disk / "replay.hlvsrec"
    world = _two_robots()
    caplog.set_level(logging.ERROR, logger="simulator.recorder")
    seconds = 20.0
    with Recorder(path, world, match_id="full", rate_hz=25.0) as recorder:
        for _ in range(int(seconds * 125)):
            world.step()
            recorder.record(world, {"state": "PLAYING"})
            if world.sim_time_ms % 1000 == 0:
                recorder.event({"type": "tick", "sim_time_ms": world.sim_time_ms})
    assert world.sim_time_ms == int(seconds * 1000)  # the match went on to its end
    assert recorder.cut.startswith(f"{path}: No space left on device: the replay ends before ")
    cut_ms = int(recorder.cut.split("ends before ")[1].split(" ms")[0])
    assert 0 < cut_ms < seconds * 1000
    assert any("replay cut short" in r.getMessage() for r in caplog.records)
    replay = load_replay(path)  # scanned: no index at the end
    times = [f.sim_time_ms for f in replay.frames]
    assert times[0] == 0 and times == sorted(times)
    assert 0 < times[-1] <= cut_ms


def test_a_match_on_a_full_disk_plays_to_its_end_with_its_results(filling_disk: Path) -> None:
    """The simulator itself (robots on loopback), its disk filling during the match: the match
    plays out and its results are written (in the space reserved for them at the start); the
    replay and the referee's logs are cut and the log says so."""
    from tests.integration.api.match_specs import short_spec
    from tests.integration.api.test_api_runtime import _play

    spec = short_spec(stepping="lockstep")
    replay_path = filling_disk / "out" / "replay.hlvsrec"
    filled = threading.Event()

    def has_frames() -> bool:
        try:
            return len(load_replay(replay_path).frames) > 1
        except (OSError, ReplayError):  # not there yet, or its header half written
            return False

    def fill_once_recording() -> None:  # the disk fills once the replay has a chunk
        deadline = time.monotonic() + 60
        while time.monotonic() < deadline:
            if replay_path.exists() and has_frames():
                with contextlib.suppress(OSError), (filling_disk / "more").open("wb") as more:
                    while True:
                        more.write(b"\0" * 4096)
                        more.flush()
                filled.set()
                return
            time.sleep(0.005)

    filler = threading.Thread(target=fill_once_recording)
    filler.start()
    code, trace = _play(spec, filling_disk / "out")
    filler.join()
    assert filled.is_set()
    assert code == 0
    assert len(trace) > 100  # the robot was served to the end
    result = json.loads((filling_disk / "out" / "sim_result.json").read_text())
    assert result["state"] == "FINISHED" and result["stop_reason"] == "finished", result
    replay = load_replay(filling_disk / "out" / "replay.hlvsrec")
    assert replay.frames[-1].sim_time_ms < result["sim_time_ms"]
    assert not (filling_disk / "out" / ".results-reserve").exists()


def test_the_orchestrator_on_a_disk_that_fills_writes_its_results_and_report(
        tmp_path: Path) -> None:
    """The runner (engine and simulator faked, the disk real) whose output folder's disk fills
    as the simulator ends: collection names each copy it could not make and still writes
    ``results.json`` and ``report.json`` (before, writing them raised ``OSError`` out of the
    runner)."""
    from contracts.files import RESERVE_BYTES, RESERVE_FILE
    from orchestrator.match.fake import FakeRuntime
    from tests.unit.match.test_match_runner import _plan, _run

    disk = _nearly_full(tmp_path / "disk", RESERVE_BYTES + 256 * 1024)
    try:
        class FillingRuntime(FakeRuntime):
            def _finish_simulator(self, found: Any) -> None:
                super()._finish_simulator(found)  # its results, then the disk is full
                with contextlib.suppress(OSError), (disk / "more").open("wb") as more:
                    while True:
                        more.write(b"\0" * 4096)
                        more.flush()

        runtime = FillingRuntime()
        _, outcome = _run(disk / "out", _plan(), runtime)
        report = json.loads((disk / "out" / "report.json").read_text())
        results = json.loads((disk / "out" / "results.json").read_text())
        assert report["status"] == "failed", report  # the logs could not be collected
        assert results["match_id"] == "u1" and results["final_state"] == "FINISHED", results
        assert outcome.failure is not None and "No space left" in outcome.failure.cause
        assert not (disk / "out" / RESERVE_FILE).exists()
    finally:
        subprocess.run(["umount", "--lazy", str(disk)], check=True)
