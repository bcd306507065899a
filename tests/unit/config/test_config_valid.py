"""Valid configurations: the examples, real HLVS files unchanged, and what they load into."""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import pytest

from orchestrator.config import (
    DEFAULT_MODEL,
    FieldClass,
    StartingPose,
    default_match_id,
    default_seed,
    load_game,
    load_team,
)
from orchestrator.errors import ConfigError
from tests.unit.config.conftest import EXAMPLES, FIXTURES, GameFiles

HLVS = FIXTURES / "hlvs"
EXAMPLE_GAMES = sorted(EXAMPLES.glob("*/game.json"))


def test_the_three_examples_exist() -> None:
    names = {p.parent.name for p in EXAMPLE_GAMES}
    assert {"kid_4v4_official", "scrimmage_1v1", "adult_3v3"} <= names


@pytest.mark.parametrize("path", EXAMPLE_GAMES, ids=[p.parent.name for p in EXAMPLE_GAMES])
def test_every_example_loads_for_a_match(path: Path, hlvs_check: Any) -> None:
    loaded = load_game(path, images_required=True)
    assert loaded.warnings == ()
    for color in ("red", "blue"):
        for player in loaded.team(color).players:
            assert player.image and ":" in player.image
    run = hlvs_check(path, "--require-images")
    assert run.code == 0, run.out
    assert run.out.strip().endswith("ok (game)")


def test_official_example_values() -> None:
    loaded = load_game(EXAMPLES / "kid_4v4_official" / "game.json")
    game = loaded.game
    assert game.red.ports == (10001, 10002, 10003, 10004)
    assert game.blue.ports == (10021, 10022, 10023, 10024)
    assert game.timing.half_duration_s == 600
    assert game.timing.wait_before_first_ready_s == 120
    assert len(loaded.red.players) == 4
    assert loaded.red.registry_auth is not None
    assert loaded.red.registry_auth.password_from({"RED_ROBOTS_REGISTRY_PASSWORD": "s3"}) == "s3"
    assert loaded.blue.registry_auth is not None and loaded.blue.registry_auth.ecr is not None


def test_scrimmage_example_is_short_and_lockstep() -> None:
    game = load_game(EXAMPLES / "scrimmage_1v1" / "game.json").game
    assert game.stepping == "lockstep"
    assert game.timing.half_duration_s <= 60
    assert game.timing.wait_before_first_ready_s <= 2


def test_adult_example_uses_adult_models_and_gc_durations() -> None:
    loaded = load_game(EXAMPLES / "adult_3v3" / "game.json")
    assert loaded.game.field_class == FieldClass.ADULT
    assert {p.model for p in loaded.red.players} == {"adult-default"}
    assert loaded.game.timing.overtime_half_duration_s == 300


def test_hlvs_game_json_validates_unchanged(hlvs_check: Any) -> None:
    loaded = load_game(HLVS / "game.json")
    game = loaded.game
    assert (game.game_type, game.field_class, game.side_left, game.kickoff) == (
        "NORMAL",
        FieldClass.KID,
        "blue",
        "red",
    )
    assert game.red.team_id == 8 and game.blue.team_id == 25
    assert game.red.config == HLVS / "team_1.json"
    assert loaded.red.name == "Bit-Bots"
    assert hlvs_check(HLVS / "game.json").code == 0


def test_hlvs_bitbots_team_values() -> None:
    team = load_team(HLVS / "team_1.json", field_class=FieldClass.KID).team
    goalie = team.player(1)
    assert goalie.proto == "WolfgangRobocup"
    assert goalie.docker_cmd == "start goalie 0"
    assert goalie.docker_cmd_args == ("start", "goalie", "0")
    assert goalie.model == DEFAULT_MODEL[FieldClass.KID]
    assert goalie.half_time_pose.yaw_rad == pytest.approx(1.57)  # [0, -0, -1, -1.57]
    assert goalie.goalkeeper_pose.x_m == pytest.approx(-4.475)
    assert goalie.image is None  # HLVS files do not name the repository


def test_hlvs_tests_style_game_loads_with_warnings(hlvs_check: Any) -> None:
    loaded = load_game(HLVS / "game_tests_style.json")
    game = loaded.game
    assert game.maximum_real_time_factor == 0
    assert game.timing.wait_before_first_ready_s == 5  # as fast as possible: short waits
    assert game.blue.team_id == 5  # "5" converted
    assert loaded.blue.players == ()
    pointers = {p.pointer for p in loaded.warnings}
    assert {"/minimum_real_time_factor", "/record_simulation", "/blue/id", "/players"} <= pointers
    run = hlvs_check(HLVS / "game_tests_style.json")
    assert run.code == 0
    assert "warning: " in run.out and "legacy field" in run.out


def test_match_id_and_seed_defaults_are_deterministic(game_files: GameFiles) -> None:
    first = load_game(game_files.write()).game
    second = load_game(game_files.write()).game
    assert first.match_id == "game-8-vs-25" == default_match_id(Path("game.json"), 8, 25)
    assert first.seed == second.seed == default_seed("game-8-vs-25")
    assert 0 <= first.seed < 2**32
    assert default_seed("other") != first.seed


def test_explicit_seed_match_id_and_legacy_random_seed(game_files: GameFiles) -> None:
    game_files.game["match_id"] = "final-1"
    game_files.game["random_seed"] = 123
    loaded = load_game(game_files.write())
    assert (loaded.game.match_id, loaded.game.seed) == ("final-1", 123)
    assert any(p.pointer == "/random_seed" for p in loaded.warnings)
    game_files.game["seed"] = 7
    assert load_game(game_files.write()).game.seed == 7


def test_game_controller_durations_set_timing(game_files: GameFiles) -> None:
    game_files.game["game_controller_extra_args"] = [
        "--halftimeduration",
        "120",
        "--overtimeduration=60",
        "--fast",
    ]
    game_files.game["max_duration"] = 900
    loaded = load_game(game_files.write())
    timing = loaded.game.timing
    assert (timing.half_duration_s, timing.overtime_half_duration_s) == (120, 60)
    assert timing.max_duration_s == 900
    assert [p.pointer for p in loaded.warnings] == ["/game_controller_extra_args/3"]


def test_defaults_of_our_additions(game_files: GameFiles) -> None:
    game = load_game(game_files.write()).game
    assert (game.stepping, game.physics_dt_s, game.allow_internet) == ("async", 0.002, False)
    assert (game.side_left, game.kickoff) == ("random", "random")
    assert game.limits.cpus == 4 and game.limits.team_comm_mb_s == 1
    assert game.timing.removal_penalty_s == 30 and game.timing.grace_period_s == 120


def test_player_image_override_model_and_display_name(game_files: GameFiles) -> None:
    game_files.game["class"] = "ADULT"
    del game_files.red["players"]["4"]
    del game_files.blue["players"]["4"]
    game_files.red["name"] = "A Very Long Team Name"
    game_files.red["players"]["2"]["image"] = "127.0.0.1:5000/other/robot"
    game_files.red["players"]["3"]["model"] = "kid-default"
    loaded = load_game(game_files.write(), images_required=True)
    red = loaded.red
    assert red.display_name == "A Very Long "
    assert red.player(1).image == "127.0.0.1:5000/test-team/robot:v1"
    assert red.player(2).image == "127.0.0.1:5000/other/robot:v1"
    assert [p.model for p in red.players] == ["adult-default", "adult-default", "kid-default"]


def test_team_ids_as_strings_are_converted(game_files: GameFiles) -> None:
    game_files.game["red"]["id"] = "12"
    assert load_game(game_files.write()).game.red.team_id == 12


def test_credentials_path_resolves_next_to_game(game_files: GameFiles) -> None:
    (game_files.folder / "red_credentials.json").write_text(
        json.dumps({"type": "s3", "credentials": {}}), encoding="utf-8"
    )
    game_files.game["red"]["credentials"] = "red_credentials.json"
    game = load_game(game_files.write()).game
    assert game.red.credentials == game_files.folder / "red_credentials.json"
    assert game.blue.credentials is None


def test_load_team_raises_with_problems(tmp_path: Path) -> None:
    path = tmp_path / "team.json"
    path.write_text('{"name": "x", "players": {"2": {}}}', encoding="utf-8")
    with pytest.raises(ConfigError) as raised:
        load_team(path)
    assert any(p.pointer.startswith("/players/2") for p in raised.value.problems)


@pytest.mark.parametrize(
    ("rotation", "yaw"),
    [
        ((0.0, 0.0, 1.0, 1.57), 1.57),
        ((0.0, -0.0, -1.0, -1.57), 1.57),
        ((0.0, 0.0, -1.0, 0.5), -0.5),
        ((0.0, 0.0, 1.0, 0.0), 0.0),
        ((0.0, 0.0, 2.0, math.pi / 4), math.pi / 4),
    ],
)
def test_yaw_from_axis_angle(rotation: tuple[float, float, float, float], yaw: float) -> None:
    pose = StartingPose(translation=(0.0, 0.0, 0.4), rotation=rotation)
    assert pose.yaw_rad == pytest.approx(yaw)
