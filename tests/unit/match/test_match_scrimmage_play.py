"""The default scrimmage's files (football in about two minutes, official timings untouched)
and the typed ``play`` record of results.json."""

from __future__ import annotations

import argparse
import json
from pathlib import Path
from typing import Any

import pytest

from contracts.errors import ContractError
from contracts.match_results import MatchLimits
from contracts.sim_result import SimResult
from orchestrator import add_scrimmage_arguments as add_arguments
from orchestrator.config.loader import load_game
from orchestrator.errors import ConfigError
from orchestrator.match.results import build_results
from orchestrator.match.scrimmage import ScrimmageRequest, write_files

PLAY = {
    "halves_playing": [1, 2], "both_halves_playing": True, "playing_s": 73.4,
    "kicks": {"red": 2, "blue": 1}, "shots": {"red": 1, "blue": 0},
    "goals": {"red": 1, "blue": 0}, "own_goals": {"red": 0, "blue": 0},
    "falls": {"red": 0, "blue": 2},
}


def _scrimmage(tmp_path: Path, *argv: str) -> tuple[dict[str, Any], dict[str, Any]]:
    parser = argparse.ArgumentParser()
    add_arguments(parser)
    request = ScrimmageRequest.from_options(parser.parse_args(list(argv)))
    game = write_files(request, tmp_path, stub_image="stub:1")
    red = json.loads((tmp_path / "team_red.json").read_text())
    return json.loads(game.read_text()), red


def test_default_scrimmage_is_a_short_game_with_a_short_ready(tmp_path: Path) -> None:
    game, red = _scrimmage(tmp_path)
    assert game["timing"]["half_duration_s"] == 40 and game["timing"]["ready_duration_s"] == 20
    assert game["stepping"] == "lockstep"
    assert [p["dockerCmd"].split()[0] for p in red["players"].values()] == ["striker"]
    loaded = load_game(tmp_path / "game.json").game
    assert loaded.timing.ready_duration_s == 20.0 and loaded.timing.half_duration_s == 40.0


def test_scrimmage_stepping_can_be_pipelined(tmp_path: Path) -> None:
    game, _red = _scrimmage(tmp_path, "--stepping", "pipelined")
    assert game["stepping"] == "pipelined"
    assert load_game(tmp_path / "game.json").game.stepping == "pipelined"


def test_larger_scrimmage_teams_add_a_goalie_then_defenders(tmp_path: Path) -> None:
    _game, red = _scrimmage(tmp_path, "--players", "4")
    roles = [p["dockerCmd"].split()[0] for p in red["players"].values()]
    assert roles == ["goalie", "striker", "defender", "defender"]


def test_adult_models_play_on_the_adult_field(tmp_path: Path) -> None:
    """A scrimmage of adult-default robots is an ADULT game: the config check passes it (robot
    heights and poses of the adult field) and every stub is told the field and the model."""
    game, red = _scrimmage(tmp_path, "--red-model", "adult-default", "--blue-model",
                           "adult-default", "--players", "3")
    assert game["class"] == "ADULT"
    loaded = load_game(tmp_path / "game.json")
    assert loaded.game.field_class.value == "adult"
    assert {p.model for t in (loaded.red, loaded.blue) for p in t.players} == {"adult-default"}
    for player in red["players"].values():
        assert player["dockerCmd"].endswith(" --model adult-default --field-class adult")
        x, y, z = player["halfTimeStartingPose"]["translation"]
        assert -7.0 < x < 0 and y == -4.6 and z == 0.9  # the own half's touch line, outside
    striker = red["players"]["2"]["dockerCmd"].split()
    assert striker[:5] == ["striker", "--start-pose", "-1.55", "-4.6", "1.57"]


def test_adult_class_given_alone_plays_the_adult_built_in(tmp_path: Path) -> None:
    game, red = _scrimmage(tmp_path, "--class", "adult")
    assert game["class"] == "ADULT"
    loaded = load_game(tmp_path / "game.json")
    assert {p.model for p in loaded.red.players} == {"adult-default"}
    assert red["players"]["1"]["dockerCmd"].endswith(" --model adult-default --field-class adult")


def test_adult_scrimmage_halves_and_ready_are_longer_unless_given(tmp_path: Path) -> None:
    """The adult field is half again as long as the kid's and the stubs walk as fast: its
    scrimmage plays 60 s halves with a 30 s READY; given durations are played as given."""
    game, _red = _scrimmage(tmp_path, "--red-model", "adult-default")
    assert game["timing"]["half_duration_s"] == 60 and game["timing"]["ready_duration_s"] == 30
    timing = load_game(tmp_path / "game.json").game.timing
    assert timing.half_duration_s == 60.0 and timing.ready_duration_s == 30.0
    game, _red = _scrimmage(tmp_path, "--class", "adult", "--half-duration", "40")
    # the clock stands still in READY, so a shorter half keeps its READY (no longer cut to fit)
    assert game["timing"]["half_duration_s"] == 40 and game["timing"]["ready_duration_s"] == 30
    game, _red = _scrimmage(tmp_path, "--class", "adult", "--ready-duration", "12")
    assert game["timing"]["half_duration_s"] == 60 and game["timing"]["ready_duration_s"] == 12


def test_four_players_do_not_fit_the_adult_field(tmp_path: Path) -> None:
    with pytest.raises(ConfigError) as raised:
        _scrimmage(tmp_path, "--class", "adult", "--players", "4")
    assert "--players" in str(raised.value) and "3" in str(raised.value)


def test_official_timings_are_the_rules(tmp_path: Path) -> None:
    game, _red = _scrimmage(tmp_path)
    del game["timing"]
    (tmp_path / "game.json").write_text(json.dumps(game))
    timing = load_game(tmp_path / "game.json").game.timing
    assert timing.ready_duration_s == 45.0 and timing.half_duration_s == 600.0


def _sim_result(play: dict[str, Any]) -> dict[str, Any]:
    return {"match_id": "m", "seed": 1, "state": "FINISHED", "score": {"red": 1, "blue": 0},
            "winner": "red", "play": play}


LIMITS = MatchLimits(cpus=4.0, memory_gb=16.0, pids=1024, log_folder_gb=10.0,
                     team_api_mb_s=350.0, team_comm_mb_s=1.0, grace_period_s=5.0,
                     allow_internet=False, host_controls=None)


def test_play_record_round_trip_and_results() -> None:
    sim = SimResult.from_dict(_sim_result(PLAY), source="sim_result.json")
    assert sim.play is not None and sim.play.both_halves_playing
    assert sim.play.kicks == {"red": 2, "blue": 1}
    results = build_results(
        match_id="m", seed=1, sim_result=sim, robots=[], forfeit=None, limits=LIMITS,
        versions={}, timings_s={}, failure=None,
    ).to_dict()
    assert results["play"] == PLAY
    old = dict(_sim_result(PLAY))
    del old["play"]  # a simulator that did not count play
    assert build_results(
        match_id="m", seed=1, sim_result=SimResult.from_dict(old), robots=[], forfeit=None,
        limits=LIMITS, versions={}, timings_s={}, failure=None,
    ).to_dict()["play"] is None


@pytest.mark.parametrize(
    ("broken", "pointer"),
    [({"kicks": {"red": 1}}, "/play"), ({"halves_playing": "1,2"}, "/play/halves_playing"),
     ({"falls": {"red": -1, "blue": 0}}, "/play"), ({"playing_s": None}, "/play/playing_s"),
     ({"both_halves_playing": False}, "/play"), ({"dribbles": 3}, "/play/dribbles")],
)
def test_a_broken_play_record_is_refused_naming_the_field(
    broken: dict[str, Any], pointer: str
) -> None:
    with pytest.raises(ContractError) as info:
        SimResult.from_dict(_sim_result({**PLAY, **broken}), source="sim_result.json")
    assert info.value.pointer == pointer and info.value.source == "sim_result.json"
