"""Fault: the match's disk fills while the simulator records the replay (a real file system: a
small tmpfs of the test's own, nearly filled).

Outcome: the match goes on (before, the write's ``OSError`` ended the match loop as an internal
error, and closing the recorder raised it again, so the simulator died without its results);
the replay keeps every whole chunk written before the disk filled and still loads (a reader
scans a file without an index); the recorder's ``cut`` names the file, the error and the
simulated time from which the replay is missing, and the simulator's log says so. The loss is
the replay's tail, named."""

from __future__ import annotations

import logging
import os
import subprocess
from collections.abc import Iterator
from pathlib import Path

import pytest

from referee.snapshot import PlaceBall
from simulator.recorder import Recorder
from simulator.replay import load_replay
from simulator.world import World
from tests.unit.world.conftest import eight_robots

pytestmark = [pytest.mark.root, pytest.mark.slow,
              pytest.mark.skipif(os.geteuid() != 0, reason="mounts a tmpfs")]


@pytest.fixture
def full_disk(tmp_path: Path) -> Iterator[Path]:
    """A 1 MiB tmpfs with about 40 KiB left (the replay's header takes about 27 KiB)."""
    mount = tmp_path / "disk"
    mount.mkdir()
    subprocess.run(["mount", "-t", "tmpfs", "-o", "size=1m", "tmpfs", str(mount)], check=True)
    try:
        free = os.statvfs(mount).f_bavail * os.statvfs(mount).f_frsize
        (mount / "filler").write_bytes(b"\0" * (free - 40 * 1024))
        yield mount
    finally:
        subprocess.run(["umount", "--lazy", str(mount)], check=True)


def test_a_full_disk_cuts_the_replay_never_the_match(
        full_disk: Path, caplog: pytest.LogCaptureFixture) -> None:
    path = full_disk / "replay.hlvsrec"
    world = World.create(field_class="kid", robots=eight_robots()[:2], seed=5)
    world.apply(PlaceBall(position=(0.0, 0.0, 0.07), velocity=(1.0, 2.0, 0.0)))
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
