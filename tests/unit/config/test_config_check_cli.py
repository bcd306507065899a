"""`hlvs check`: kinds found from the content, --kind, the credentials and schedule loaders."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest

from tests.unit.config.conftest import EXAMPLES, GameFiles, valid_team


def test_game_and_team_files_in_one_call(game_files: GameFiles, hlvs_check: Any) -> None:
    game = game_files.write()
    run = hlvs_check(game, game_files.folder / "team_red.json")
    assert run.code == 0
    assert f"{game}: ok (game)" in run.out
    assert "team_red.json: ok (team)" in run.out


def test_one_bad_file_makes_the_exit_code_2(game_files: GameFiles, hlvs_check: Any) -> None:
    game = game_files.write()
    bad = game_files.folder / "bad.json"
    bad.write_text("{", encoding="utf-8")
    run = hlvs_check(game, bad)
    assert run.code == 2
    assert f"{game}: ok (game)" in run.out
    assert f"{bad}: invalid JSON at line 1 column 2" in run.out


def test_missing_file_and_directory_are_one_line_each(tmp_path: Path, hlvs_check: Any) -> None:
    run = hlvs_check(tmp_path / "missing.json", tmp_path)
    assert run.code == 2
    lines = run.out.splitlines()
    assert lines == [
        f"{tmp_path / 'missing.json'}: file not found",
        f"{tmp_path}: is a directory (expected a file)",
    ]


def test_unknown_kind_asks_for_kind(tmp_path: Path, hlvs_check: Any) -> None:
    path = tmp_path / "what.json"
    path.write_text('{"colour": "red"}', encoding="utf-8")
    run = hlvs_check(path)
    assert run.code == 2
    assert "cannot tell which kind of file this is" in run.out and "--kind" in run.out


def test_forced_kind_checks_as_that_kind(tmp_path: Path, hlvs_check: Any) -> None:
    path = tmp_path / "team.json"
    path.write_text(json.dumps({"nam": "x", "players": {}}), encoding="utf-8")
    run = hlvs_check("--kind", "team", path)
    assert run.code == 2
    assert f'{path}: /nam: unknown field "nam" (did you mean "name"?)' in run.out
    run = hlvs_check("--kind", "game", path)
    assert run.code == 2
    assert f"{path}: /type: required field is missing" in run.out


def test_team_checked_alone_with_class(tmp_path: Path, hlvs_check: Any) -> None:
    path = tmp_path / "team.json"
    path.write_text(json.dumps(valid_team(4)), encoding="utf-8")
    assert hlvs_check(path).code == 0
    run = hlvs_check("--class", "ADULT", path)
    assert run.code == 2
    assert f"{path}: /players/4: 4 players: too many for ADULT class" in run.out


def test_missing_images_are_warnings_unless_required(tmp_path: Path, hlvs_check: Any) -> None:
    team = valid_team(2)
    del team["image"]
    path = tmp_path / "team.json"
    path.write_text(json.dumps(team), encoding="utf-8")
    run = hlvs_check(path)
    assert run.code == 0
    assert f"warning: {path}: /image: " in run.out
    run = hlvs_check("--require-images", path)
    assert run.code == 2
    assert f"{path}: /players/2/image: no image named for this player" in run.out


def test_credentials_file_is_checked(tmp_path: Path, hlvs_check: Any) -> None:
    pytest.importorskip("orchestrator.config.credentials")
    examples = sorted((EXAMPLES / "credentials").glob("s3*.json"))
    assert examples
    assert hlvs_check(*examples).code == 0
    bad = tmp_path / "credentials.json"
    bad.write_text(json.dumps({"type": "ftp", "credentials": {}}), encoding="utf-8")
    run = hlvs_check(bad)
    assert run.code == 2
    assert f"{bad}: /type" in run.out


def test_schedule_file_is_checked(tmp_path: Path, hlvs_check: Any) -> None:
    pytest.importorskip("orchestrator.config.schedule")
    bad = tmp_path / "schedule.yaml"
    bad.write_text("matches: 3\n", encoding="utf-8")
    run = hlvs_check(bad)
    assert run.code == 2
    assert str(bad) in run.out
    assert "Traceback" not in run.out


def test_device_file_is_not_read(hlvs_check: Any) -> None:
    run = hlvs_check("/dev/zero")
    assert run.code == 2
    assert run.out.splitlines() == ["/dev/zero: not a regular file (expected a file)"]


def test_game_check_includes_referenced_credentials(game_files: GameFiles, hlvs_check: Any) -> None:
    pytest.importorskip("orchestrator.config.credentials")
    creds = game_files.folder / "red_credentials.json"
    creds.write_text(json.dumps({"type": "s3", "credentials": {}}), encoding="utf-8")
    game_files.game["red"]["credentials"] = "red_credentials.json"
    run = hlvs_check(game_files.write())
    assert run.code == 2
    assert f"{creds}: /credentials" in run.out
    creds.write_bytes(b"\xff\xfe\x00binary")
    run = hlvs_check(game_files.write())
    assert run.code == 2
    assert f"{creds}: binary file" in run.out
