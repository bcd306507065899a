"""The header's robots are :class:`RobotEntry` values, read with the contract codec: a robot that
does not fit is refused naming the file and the field."""

from __future__ import annotations

import json
import struct
from pathlib import Path

import pytest

from contracts.codec import to_data
from simulator.errors import ReplayError
from simulator.replay import RobotEntry, load_replay
from simulator.replay.format import MAGIC

FIXTURE = Path(__file__).parent / "fixtures" / "v2-two-robots.hlvsrec"


def _with_header(path: Path, edit: dict[str, object]) -> Path:
    """A copy of the version 2 fixture whose header has ``edit`` merged into it."""
    blob = FIXTURE.read_bytes()
    (length,) = struct.unpack("<I", blob[len(MAGIC) : len(MAGIC) + 4])
    start = len(MAGIC) + 4
    header = json.loads(blob[start : start + length])
    header.update(edit)
    raw = json.dumps(header).encode()
    path.write_bytes(MAGIC + struct.pack("<I", len(raw)) + raw + blob[start + length :])
    return path


def test_header_robots_read_back_as_the_entries_written() -> None:
    robots = load_replay(FIXTURE).header.robots
    assert robots[0] == RobotEntry(team="red", number=1, model="kid-default", x_m=-1.6,
                                   y_m=-1.5, yaw_rad=0.0)  # fmt: skip
    assert robots[0].key == "red_1"
    assert to_data(robots[0]) == {"team": "red", "number": 1, "model": "kid-default",
                                  "x_m": -1.6, "y_m": -1.5, "yaw_rad": 0.0}  # fmt: skip


def test_a_robot_that_does_not_fit_names_the_file_and_field(tmp_path: Path) -> None:
    bad = {"team": "red", "number": 1, "model": "kid-default", "x_m": "left", "y_m": 0.0,
           "yaw_rad": 0.0}  # fmt: skip
    path = _with_header(tmp_path / "bad.hlvsrec", {"robots": [bad]})
    with pytest.raises(ReplayError) as caught:
        load_replay(path)
    assert str(path) in str(caught.value) and "/robots/0/x_m" in str(caught.value)
