"""Helpers for the config tests: valid documents to break, and running ``hlvs check``."""

from __future__ import annotations

import copy
import json
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import pytest

from hlvs.cli import main

FIXTURES = Path(__file__).parent / "fixtures"
REPO = Path(__file__).resolve().parents[3]
EXAMPLES = REPO / "configs" / "examples"


def _pose(x: float, y: float, angle: float) -> dict[str, Any]:
    return {"translation": [x, y, 0.43], "rotation": [0, 0, 1, angle]}


def valid_team(players: int = 4) -> dict[str, Any]:
    spots = [(-4.0, -3.1, 1.57), (-1.0, -3.1, 1.57), (-1.0, 3.1, -1.57), (-3.0, 3.1, -1.57)]
    return {
        "name": "Test Team",
        "image": "127.0.0.1:5000/test-team/robot",
        "players": {
            str(n): {
                "proto": "TestBot",
                "dockerTag": "v1",
                "dockerCmd": f"start --player {n}",
                "halfTimeStartingPose": _pose(*spots[n - 1]),
                "reentryStartingPose": _pose(*spots[n - 1]),
                "shootoutStartingPose": _pose(2.6, 0.0, 0.0),
                "goalKeeperStartingPose": _pose(-4.45, 0.0, 0.0),
            }
            for n in range(1, players + 1)
        },
    }


def valid_game() -> dict[str, Any]:
    return {
        "type": "NORMAL",
        "class": "KID",
        "host": "127.0.0.1",
        "maximum_real_time_factor": 1.0,
        "red": {
            "id": 8,
            "config": "team_red.json",
            "hosts": ["127.0.0.1"],
            "ports": [10001, 10002, 10003, 10004],
        },
        "blue": {
            "id": 25,
            "config": "team_blue.json",
            "hosts": ["127.0.0.1"],
            "ports": [10021, 10022, 10023, 10024],
        },
    }


@dataclass
class GameFiles:
    folder: Path
    game: dict[str, Any]
    red: dict[str, Any]
    blue: dict[str, Any]
    raw: dict[str, bytes] = field(default_factory=dict)  # file name -> bytes written instead

    def write(self) -> Path:
        for name, doc in (
            ("game.json", self.game),
            ("team_red.json", self.red),
            ("team_blue.json", self.blue),
        ):
            (self.folder / name).write_text(json.dumps(doc, indent=2), encoding="utf-8")
        return self.folder / "game.json"


@pytest.fixture
def game_files(tmp_path: Path) -> GameFiles:
    return GameFiles(tmp_path, valid_game(), valid_team(), copy.deepcopy(valid_team()))


@dataclass
class CheckRun:
    code: int
    out: str
    err: str


@pytest.fixture
def hlvs_check(capsys: pytest.CaptureFixture[str]) -> Callable[..., CheckRun]:
    def run(*args: str | Path) -> CheckRun:
        capsys.readouterr()
        code = main(["check", *(str(a) for a in args)])
        captured = capsys.readouterr()
        assert "Traceback" not in captured.out + captured.err
        return CheckRun(code, captured.out, captured.err)

    return run
