"""to_match_spec builds the MatchSpec the simulator reads, with random choices from the seed."""

from __future__ import annotations

import json
import subprocess
import sys

import pytest

from contracts.match_spec import MatchSpec
from orchestrator.config import load_game, resolve_sides, to_match_spec
from tests.unit.config.conftest import EXAMPLES, GameFiles


@pytest.mark.parametrize("example", ["kid_4v4_official", "scrimmage_1v1", "adult_3v3"])
def test_round_trip_through_match_spec(example: str) -> None:
    loaded = load_game(EXAMPLES / example / "game.json")
    addresses = {
        "red": [f"172.30.1.{n}" for n in range(1, len(loaded.red.players) + 1)],
        "blue": [f"172.30.2.{n}" for n in range(1, len(loaded.blue.players) + 1)],
    }
    data = to_match_spec(loaded, robot_addresses=addresses, telemetry_listen="tcp/172.30.0.2:7447")
    spec = MatchSpec.from_dict(json.loads(data.to_json()))
    game = loaded.game
    assert (spec.match_id, spec.seed, spec.game_type) == (game.match_id, game.seed, game.game_type)
    assert spec.field_class == game.field_class.value
    assert spec.stepping == game.stepping
    assert spec.network.telemetry_listen == "tcp/172.30.0.2:7447"
    assert spec.timing.half_duration_s == game.timing.half_duration_s
    assert spec.timing.wait_before_first_ready_real_s == game.timing.wait_before_first_ready_s
    for color in ("red", "blue"):
        team = spec.team(color)
        ref = game.team(color)
        config = loaded.team(color)
        assert team.team_id == ref.team_id
        assert team.robot_addresses == tuple(addresses[color])
        assert set(addresses[color]) <= set(team.hosts)
        assert [p.port for p in team.players] == list(ref.ports[: len(config.players)])
        for player, source in zip(team.players, config.players, strict=True):
            assert player.model == source.model
            assert player.half_time_pose.x_m == source.half_time_pose.x_m
            assert player.half_time_pose.yaw_rad == pytest.approx(source.half_time_pose.yaw_rad)
            assert player.goalkeeper == (player.number == 1)


def test_video_only_for_mp4(game_files: GameFiles) -> None:
    game_files.game["record_simulation"] = "/tmp/anything.mp4"
    loaded = load_game(game_files.write())
    data = to_match_spec(loaded, robot_addresses={}, telemetry_listen=None)
    assert MatchSpec.from_dict(data.to_dict()).record_video == "match.mp4"
    game_files.game["record_simulation"] = "recording.html"
    loaded = load_game(game_files.write())
    assert to_match_spec(loaded, robot_addresses={}, telemetry_listen=None).record_video is None


def test_random_sides_follow_the_seed(game_files: GameFiles) -> None:
    outcomes = set()
    for seed in range(40):
        game_files.game["seed"] = seed
        loaded = load_game(game_files.write())
        first = resolve_sides(loaded)
        assert resolve_sides(loaded) == first  # same seed, same choice
        data = to_match_spec(loaded, robot_addresses={}, telemetry_listen=None)
        assert (data.side_left, data.kickoff) == first
        outcomes.add(first)
    assert len(outcomes) == 4  # every combination happens for some seed


def test_fixed_sides_are_kept(game_files: GameFiles) -> None:
    game_files.game["side_left"] = "blue"
    game_files.game["kickoff"] = "red"
    loaded = load_game(game_files.write())
    assert resolve_sides(loaded) == ("blue", "red")


def test_spec_module_does_not_import_the_simulator() -> None:
    code = "import sys, orchestrator.config.spec; print('simulator' in sys.modules)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "False"


def test_game_hosts_are_allowed_only_where_the_match_is_laid_out_elsewhere() -> None:
    """``hosts`` of game.json reach the spec of a simulator run outside ``hlvs match``; the
    match's own spec (its plan's builder) allows each robot's address alone."""
    from orchestrator.match import plan_from_game

    loaded = load_game(EXAMPLES / "scrimmage_1v1" / "game.json")
    addresses = {"red": ["172.30.1.1"], "blue": ["172.30.2.1"]}
    game_hosts = {color: loaded.game.team(color).hosts for color in ("red", "blue")}
    assert all(game_hosts.values())  # the example names its hosts
    elsewhere = to_match_spec(loaded, robot_addresses=addresses, telemetry_listen=None)
    laid_out = plan_from_game(loaded).spec_builder(
        {color: tuple(a) for color, a in addresses.items()}, None)
    for color in ("red", "blue"):
        assert elsewhere.team(color).hosts == tuple(
            dict.fromkeys([*game_hosts[color], *addresses[color]]))
        assert laid_out.team(color).hosts == tuple(addresses[color])
        assert laid_out.team(color).robot_addresses == tuple(addresses[color])
