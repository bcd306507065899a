"""Documents, not paths: parse_game and parse_team validate parsed JSON; no file is read."""

from __future__ import annotations

from pathlib import Path

import pytest

from orchestrator.config import FieldClass, load_game, parse_game, parse_team
from orchestrator.errors import ConfigError
from tests.unit.config.conftest import GameFiles, valid_game, valid_team


def test_documents_parse_like_their_files(game_files: GameFiles) -> None:
    from_files = load_game(game_files.write(), images_required=True)
    source = game_files.folder / "game.json"
    red = parse_team(valid_team(), source=game_files.folder / "team_red.json",
                     field_class=FieldClass.KID, images_required=True).team
    blue = parse_team(valid_team(), source=game_files.folder / "team_blue.json",
                      field_class=FieldClass.KID, images_required=True).team
    from_documents = parse_game(valid_game(), source=source, teams={"red": red, "blue": blue},
                                images_required=True)
    assert from_documents == from_files


def test_no_file_is_read_for_documents(tmp_path: Path) -> None:
    source = tmp_path / "nowhere" / "game.json"  # neither it nor its team files exist
    team = parse_team(valid_team(), source="team_config.json", field_class=FieldClass.KID).team
    loaded = parse_game(valid_game(), source=source, teams={"red": team, "blue": team})
    assert loaded.game.red.config == source.parent / "team_red.json"
    assert loaded.red.source == Path("team_config.json")


def test_a_bad_team_document_names_its_source_and_field() -> None:
    team = valid_team()
    del team["name"]
    with pytest.raises(ConfigError) as raised:
        parse_team(team, source="team_config.json")
    assert any(p.file == "team_config.json" and p.pointer in ("", "/name")
               for p in raised.value.problems)


def test_cross_file_rules_apply_to_parsed_teams() -> None:
    game = valid_game()
    game["red"]["ports"] = [10001]
    team = parse_team(valid_team(), source="team_config.json", field_class=FieldClass.KID).team
    with pytest.raises(ConfigError) as raised:
        parse_game(game, source="game.json", teams={"red": team, "blue": team})
    assert [p.pointer for p in raised.value.problems if p.severity == "error"] == ["/red/ports"]
