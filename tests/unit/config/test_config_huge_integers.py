"""An integer longer than Python reads into a number (its int-string limit, 4300 digits) in a
game.json, a team file, a credentials file or a schedule: one problem line naming the file,
the pointer and what was expected, from ``hlvs check`` and ``hlvs match`` alike, no traceback."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest

from hlvs.cli import main
from orchestrator.config.schedule import load_schedule
from orchestrator.errors import ConfigError
from tests.unit.config.conftest import GameFiles
from tests.unit.schedule.test_schedule import COMPRESSED, write_schedule

HUGE = "7" * 5000
EXPECTED = "an integer of 5000 digits, too long to read (expected a number of at most 4300 digits)"


def _with_huge(document: dict[str, Any], dotted: str) -> str:
    """``document`` as JSON text with the value at ``dotted`` (keys joined by dots) written as
    the huge integer."""
    marker = "__HUGE__"
    *parents, last = dotted.split(".")
    node: Any = document
    for key in parents:
        node = node[int(key)] if isinstance(node, list) else node[key]
    if isinstance(node, list):
        node[int(last)] = marker
    else:
        node[last] = marker
    return json.dumps(document, indent=2).replace(f'"{marker}"', HUGE)


def test_in_game_json(game_files: GameFiles, hlvs_check: Any) -> None:
    path = game_files.write()
    path.write_text(_with_huge(game_files.game, "red.id"))
    run = hlvs_check(path)
    assert run.code == 2
    assert f"{path}: /red/id: {EXPECTED}" in run.out


def test_in_a_team_file_of_a_game(game_files: GameFiles, hlvs_check: Any) -> None:
    path = game_files.write()
    team = path.parent / "team_blue.json"
    team.write_text(_with_huge(game_files.blue, "players.1.halfTimeStartingPose.translation.0"))
    run = hlvs_check(path)
    assert run.code == 2
    assert f"{team}: /players/1/halfTimeStartingPose/translation/0: {EXPECTED}" in run.out
    run = hlvs_check(team)  # the team file alone
    assert run.code == 2
    assert f"{team}: /players/1/halfTimeStartingPose/translation/0: {EXPECTED}" in run.out


def test_hlvs_match_names_it_too(game_files: GameFiles,
                                 capsys: pytest.CaptureFixture[str]) -> None:
    path = game_files.write()
    path.write_text(_with_huge(game_files.game, "maximum_real_time_factor"))
    code = main(["match", str(path)])
    captured = capsys.readouterr()
    assert code == 2
    assert "Traceback" not in captured.out + captured.err
    assert f"{path}: /maximum_real_time_factor: {EXPECTED}" in captured.out + captured.err


def test_negative_and_in_a_credentials_file(tmp_path: Path, hlvs_check: Any) -> None:
    credentials = tmp_path / "credentials.json"
    credentials.write_text('{"protocol": "sftp", "host": "logs.example", "port": -' + HUGE + "}")
    run = hlvs_check(credentials)
    assert run.code == 2 and f"{credentials}: /port: {EXPECTED}" in run.out


def test_in_a_schedule(tmp_path: Path, hlvs_check: Any) -> None:
    path = write_schedule(tmp_path, COMPRESSED.replace("simulator_slots: 1",
                                                       f"simulator_slots: {HUGE}"))
    with pytest.raises(ConfigError) as info:
        load_schedule(path)
    [problem] = info.value.problems
    assert (problem.file, problem.pointer) == (str(path), "/simulator_slots")
    assert str(problem) == f"{path}: /simulator_slots: {EXPECTED}"
    run = hlvs_check(path)
    assert run.code == 2 and f"{path}: /simulator_slots: {EXPECTED}" in run.out


def test_an_integer_of_4300_digits_is_read_as_a_number(game_files: GameFiles,
                                                       hlvs_check: Any) -> None:
    path = game_files.write()
    path.write_text(_with_huge(game_files.game, "red.id").replace(HUGE, "9" * 4300))
    run = hlvs_check(path)
    assert "too long to read" not in run.out
    assert "/red/id" in run.out  # refused as a team number, by its value


def test_in_a_robot_model_manifest(tmp_path: Path, hlvs_check: Any) -> None:
    manifest = tmp_path / "robot_model.json"
    manifest.write_text('{"format_version": ' + HUGE + ', "name": "huge"}')
    run = hlvs_check(tmp_path)
    assert run.code == 2 and f"{manifest}: /format_version: {EXPECTED}" in run.out
