"""League files unchanged: a game.json without any real-time factor, and team files found from
the working directory as the league's referee finds them."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest

from orchestrator.config import check_game, load_game
from orchestrator.config.game import DEFAULT_MAXIMUM_REAL_TIME_FACTOR
from orchestrator.errors import ConfigError
from tests.unit.config.conftest import GameFiles


def test_no_real_time_factor_uses_the_league_default_with_a_warning(
    game_files: GameFiles, hlvs_check: Any
) -> None:
    del game_files.game["maximum_real_time_factor"]
    path = game_files.write()
    loaded = load_game(path)
    assert loaded.game.maximum_real_time_factor == DEFAULT_MAXIMUM_REAL_TIME_FACTOR == 1.0
    [warning] = [w for w in loaded.warnings if w.pointer == "/maximum_real_time_factor"]
    assert warning.severity == "warning" and "league's default 1" in warning.message
    run = hlvs_check(path)
    assert run.code == 0
    assert f"warning: {path}: /maximum_real_time_factor: missing" in run.out


def test_a_legacy_name_still_wins_over_the_default(game_files: GameFiles) -> None:
    del game_files.game["maximum_real_time_factor"]
    game_files.game["minimum_real_time_factor"] = 0
    loaded = load_game(game_files.write())
    assert loaded.game.maximum_real_time_factor == 0
    pointers = {w.pointer for w in loaded.warnings}
    assert "/minimum_real_time_factor" in pointers
    assert "/maximum_real_time_factor" not in pointers


@pytest.mark.parametrize("stepping", [None, "async", "lockstep", "pipelined"])
def test_async_as_fast_as_possible_is_warned_about(game_files: GameFiles,
                                                   stepping: str | None) -> None:
    """Async never waits for the robots: as fast as possible, a faster host leaves them fewer
    control steps. Lockstep and pipelined wait for them; real time is the league's."""
    game_files.game["maximum_real_time_factor"] = 0
    if stepping is not None:
        game_files.game["stepping"] = stepping
    fast = [w for w in load_game(game_files.write()).warnings
            if w.pointer == "/maximum_real_time_factor"]
    if stepping in (None, "async"):
        assert len(fast) == 1 and "fewer control steps" in fast[0].message, fast
    else:
        assert fast == []
    game_files.game["maximum_real_time_factor"] = 1
    assert not [w for w in load_game(game_files.write()).warnings
                if w.pointer == "/maximum_real_time_factor"]


@pytest.mark.parametrize(
    ("name", "value", "maximum"),
    [
        ("minimum_real_time_factor", 0.1, 10.0),
        ("minimum_real_time_factor", 3, 1 / 3),
        ("minimum_real_time_factor", 1, 1.0),
        ("real_time_factor", 2, 0.5),
    ],
)
def test_a_legacy_factor_is_the_least_wall_time_of_a_step(
    game_files: GameFiles, name: str, value: float, maximum: float
) -> None:
    """League referee ``controllers/referee/referee.py`` before March 2023 (and the 2021
    ``real_time_factor``): each 8 ms step lasts at least ``v`` x 8 ms of wall time ("maximum
    1 / v x speed"), so ``v`` 0.1 runs up to 10 x real time, not at 0.1 x."""
    del game_files.game["maximum_real_time_factor"]
    game_files.game[name] = value
    loaded = load_game(game_files.write())
    assert loaded.game.maximum_real_time_factor == pytest.approx(maximum)
    [warning] = [w for w in loaded.warnings if w.pointer == f"/{name}"]
    assert f"at least {value:g} x 8 ms of wall time" in warning.message


def _split_layout(game_files: GameFiles, tmp_path: Path) -> Path:
    """game.json in games/, the team files in teams/ named as seen from tmp_path (the cwd)."""
    games, teams = tmp_path / "games", tmp_path / "teams"
    games.mkdir()
    teams.mkdir()
    game_files.folder = games
    game_files.game["red"]["config"] = "teams/team_red.json"
    game_files.game["blue"]["config"] = "teams/team_blue.json"
    path = game_files.write()
    for color in ("red", "blue"):
        (games / f"team_{color}.json").rename(teams / f"team_{color}.json")
    return path


def test_team_file_found_from_the_working_directory(
    game_files: GameFiles, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    path = _split_layout(game_files, tmp_path)
    monkeypatch.chdir(tmp_path)
    loaded = load_game(path)
    assert loaded.red.source == tmp_path / "teams" / "team_red.json"
    assert loaded.game.red.config == tmp_path / "teams" / "team_red.json"
    [warning] = [w for w in loaded.warnings if w.pointer == "/red/config"]
    assert str(tmp_path / "games" / "teams" / "team_red.json") in warning.message
    assert "found in the current directory" in warning.message


def test_team_file_next_to_the_game_file_comes_first(
    game_files: GameFiles, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    path = game_files.write()  # team files next to game.json
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    (elsewhere / "team_red.json").write_text("{}")  # would be invalid if it were chosen
    monkeypatch.chdir(elsewhere)
    loaded = load_game(path)
    assert loaded.red.source == tmp_path / "team_red.json"
    assert not [w for w in loaded.warnings if w.pointer == "/red/config"]


def test_missing_team_file_names_every_place_tried(
    game_files: GameFiles, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    path = _split_layout(game_files, tmp_path)
    (tmp_path / "teams" / "team_blue.json").unlink()
    cwd = tmp_path / "somewhere"
    cwd.mkdir()
    monkeypatch.chdir(cwd)
    with pytest.raises(ConfigError) as caught:
        load_game(path)
    [problem] = [p for p in caught.value.problems if p.pointer == "/blue/config"]
    assert problem.file == str(path) and problem.severity == "error"
    assert str(tmp_path / "games" / "teams" / "team_blue.json") in problem.message
    assert str(cwd / "teams" / "team_blue.json") in problem.message
    assert "current directory" in problem.expected
    assert [p.pointer for p in check_game(path) if p.severity == "error"] == [
        "/red/config", "/blue/config",
    ]


def test_the_leagues_knockout_test_shape_is_accepted(game_files: GameFiles,
                                                      hlvs_check: Any) -> None:
    """hlvs_webots ``tests/game_phases/knockout/game.json``: 20 s halves and halves of extra
    time (``--halftimeduration 20 --overtimeduration 20``) with the rules' 45 s READY. The
    clock stands still in READY and SET before each kick-off (league GameController
    ``AdvancedData.java:291-294``), so each half plays 20 s: not refused."""
    game_files.game.update({
        "type": "KNOCKOUT", "supervisor": "test_supervisor", "minimum_real_time_factor": 0,
        "game_controller_extra_args": ["--halftimeduration", "20", "--overtimeduration", "20"],
    })
    del game_files.game["maximum_real_time_factor"]
    game_files.game.pop("timing", None)
    path = game_files.write()
    loaded = load_game(path)
    timing = loaded.game.timing
    assert (timing.half_duration_s, timing.overtime_half_duration_s) == (20, 20)
    assert timing.ready_duration_s == 45
    run = hlvs_check(path)
    assert run.code == 0, run.out
    game_files.game["game_controller_extra_args"] = ["--halftimeduration", "8"]
    run = hlvs_check(game_files.write())
    assert run.code == 2 and "/timing/half_duration_s: a half of 8 s leaves 8 s" in run.out
