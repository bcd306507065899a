"""One source of match timing (contracts.timing) on every path, and a match that did not play
classified by its cause instead of a success."""

from __future__ import annotations

import argparse
import json
import logging
from pathlib import Path
from typing import Any

import pytest

from contracts.match_results import FailureClass, MatchReport, RobotResult
from contracts.match_spec import TimingSpec
from contracts.sim_result import SimResult
from contracts.timing import (
    MIN_PLAYING_S,
    SCRIMMAGE,
    TEST_MATCH,
    TimingError,
    check_half,
    fit_ready,
    played_enough,
)
from envs.errors import EnvConfigError
from envs.session_spec import SessionSpec
from orchestrator import add_scrimmage_arguments as add_arguments
from orchestrator.config.loader import load_game
from orchestrator.errors import ConfigError
from orchestrator.match.results import RobotRecord, play_failure
from orchestrator.match.scrimmage import ScrimmageRequest, write_files
from service import Settings
from service.errors import SettingsError
from service.matchfiles import write_match
from service.submissions import failure_side


def _request(parser: argparse.ArgumentParser, argv: list[str]) -> ScrimmageRequest:
    return ScrimmageRequest.from_options(parser.parse_args(argv))


def test_every_preset_leaves_the_minimum_of_play() -> None:
    """Only the clock that runs counts: it stands still in READY and SET before each half's
    kick-off (league GameController ``AdvancedData.java:291-294``), so a half keeps all of its
    time for PLAYING, however long its READY."""
    for half in (600, SCRIMMAGE.half_duration_s, TEST_MATCH.half_duration_s, 20, 10):
        check_half(half)
    assert TEST_MATCH.playing_per_half_s == 40.0
    with pytest.raises(TimingError, match=r"a half of 8 s leaves 8 s of play"):
        check_half(8)
    check_half(8, minimum_s=0)  # a match not meant to play


def test_quick_tests_keep_their_ready_or_refuse_a_half_too_short() -> None:
    assert fit_ready(65, 20) == (20, None)
    assert fit_ready(30, 45) == (45, None)  # READY does not take from the half
    with pytest.raises(TimingError, match="too short to play"):
        fit_ready(8, 20)


def _game(tmp_path: Path, timing: dict[str, Any], game_type: str = "NORMAL") -> Path:
    parser = argparse.ArgumentParser()
    add_arguments(parser)
    game_path = write_files(_request(parser, []), tmp_path, stub_image="stub:1")
    game = json.loads(game_path.read_text())
    game["timing"] = timing
    game["type"] = game_type
    game_path.write_text(json.dumps(game))
    return game_path


def test_a_half_shorter_than_the_minimum_of_play_is_refused_not_one_shorter_than_ready(
        tmp_path: Path) -> None:
    """READY and SET before the kick-off do not count (the clock stands still in them): a half
    of 30 s with the rules' 45 s READY plays 30 s; a half of 8 s is refused."""
    assert load_game(_game(tmp_path, {"half_duration_s": 30}))  # READY: the rules' 45 s
    with pytest.raises(ConfigError) as info:
        load_game(_game(tmp_path, {"half_duration_s": 8, "ready_duration_s": 20}))
    problem = info.value.problems[0]
    assert problem.pointer == "/timing/half_duration_s"
    assert "a half of 8 s leaves 8 s of play" in problem.message
    assert problem.expected == "minimum_play_s (10 s) <= half_duration_s"
    knockout = {"half_duration_s": 65, "ready_duration_s": 20, "overtime_half_duration_s": 8}
    with pytest.raises(ConfigError, match="half of extra time"):
        load_game(_game(tmp_path, knockout, "KNOCKOUT"))
    knockout["overtime_half_duration_s"] = 20
    assert load_game(_game(tmp_path, knockout, "KNOCKOUT"))


def test_a_scrimmage_with_a_short_half_keeps_its_ready_and_one_too_short_is_refused(
        tmp_path: Path, caplog: pytest.LogCaptureFixture) -> None:
    parser = argparse.ArgumentParser()
    add_arguments(parser)
    with caplog.at_level(logging.WARNING):
        game = write_files(_request(parser, ["--half-duration", "15"]), tmp_path,
                           stub_image="stub:1")
    assert "READY" not in caplog.text
    assert load_game(game).game.timing.ready_duration_s == 20
    with pytest.raises(ConfigError, match="too short to play"):
        write_files(_request(parser, ["--half-duration", "8"]), tmp_path, stub_image="s:1")


def test_an_async_scrimmage_is_paced_to_real_time_and_a_lockstep_one_is_not(
        tmp_path: Path) -> None:
    """Async never waits for the robots: as fast as possible, a fast host would leave the
    robots a fraction of their control steps (a stub then never reaches the ball)."""
    parser = argparse.ArgumentParser()
    add_arguments(parser)
    paced = {}
    for stepping in ("async", "lockstep", "pipelined"):
        game = write_files(_request(parser, ["--stepping", stepping]), tmp_path / stepping,
                           stub_image="stub:1")
        loaded = load_game(game).game
        assert loaded.stepping == stepping
        paced[stepping] = loaded.maximum_real_time_factor
    assert paced == {"async": 1.0, "lockstep": 0.0, "pipelined": 0.0}


def test_service_test_matches_play_and_too_short_halves_are_refused(tmp_path: Path) -> None:
    settings = Settings()
    team = {"name": "A", "image": "a/robot", "players": {"1": {"dockerTag": "1"}}}
    game = write_match(tmp_path, match_id="m1", team=team, opponent=None, stub_image="stub:1",
                       settings=settings, seed=1)
    timing = json.loads(game.read_text())["timing"]
    assert timing["half_duration_s"] == 40 and timing["ready_duration_s"] == 10
    with pytest.raises(SettingsError, match="HLVS_SERVICE_TEST_HALF_DURATION_S"):
        Settings.from_env({"HLVS_SERVICE_TEST_HALF_DURATION_S": "8"})


def test_environment_matches_are_checked() -> None:
    assert SessionSpec(referee=True).ready_duration_s == 15
    assert SessionSpec(referee=True, half_duration_s=20).ready_duration_s == 15  # kept
    with pytest.raises(EnvConfigError, match="half_duration_s"):
        SessionSpec(referee=True, half_duration_s=8)
    assert SessionSpec(referee=True, half_duration_s=5, minimum_play_s=0).ready_duration_s == 15


def test_a_match_not_meant_to_play_is_neither_refused_nor_failed(tmp_path: Path) -> None:
    game = load_game(_game(tmp_path, {"half_duration_s": 4, "minimum_play_s": 0})).game
    assert game.timing.minimum_play_s == 0
    timing = TimingSpec(half_duration_s=4.0, minimum_play_s=0.0)
    assert play_failure(_sim(0.0, [], ()), ROBOTS, timing) is None


def _sim(playing_s: float, halves: list[int], connected: tuple[str, ...]) -> SimResult:
    zero = {"red": 0, "blue": 0}
    return SimResult.from_dict({
        "match_id": "m", "seed": 1, "state": "FINISHED", "score": zero, "winner": "draw",
        "robots": {key: {"connects": [1.0]} for key in connected},
        "play": {"halves_playing": halves, "both_halves_playing": {1, 2} <= set(halves),
                 "playing_s": playing_s, "kicks": zero, "shots": zero, "goals": zero,
                 "own_goals": zero, "falls": zero}})


ROBOTS = [RobotRecord(key="red-1", color="red", number=1, entry=RobotResult(image="r")),
          RobotRecord(key="blue-1", color="blue", number=1, entry=RobotResult(image="b"))]
BOTH = ("red-1", "blue-1")


def test_a_match_that_played_is_not_a_failure() -> None:
    assert played_enough([1, 2], 30.0) and not played_enough([], 0.0)
    assert not played_enough([1], MIN_PLAYING_S - 1)
    assert play_failure(_sim(30.0, [1, 2], BOTH), ROBOTS, TimingSpec()) is None


def test_no_play_by_the_leagues_timing_is_the_leagues() -> None:
    timing = TimingSpec(half_duration_s=8.0, ready_duration_s=45.0)
    failure = play_failure(_sim(0.0, [], BOTH), ROBOTS, timing)
    assert failure is not None and failure.failure_class is FailureClass.NOT_PLAYED
    assert failure.team is None and "the league's timing" in failure.cause
    report = MatchReport.of(failure)
    assert report.to_dict() == {"status": "failed", "failure_class": "not_played",
                                "cause": failure.cause}
    assert failure_side("not_played") == "league"


def test_no_play_because_a_team_never_connected_names_the_team() -> None:
    failure = play_failure(_sim(0.0, [], ("blue-1",)), ROBOTS, TimingSpec(half_duration_s=65.0))
    assert failure is not None and failure.failure_class is FailureClass.TEAM_ABSENT
    assert failure.team == "red" and "no robot of red ever connected" in failure.cause
    report = MatchReport.of(failure)
    assert report.to_dict()["team"] == "red"
    assert MatchReport.from_dict(report.to_dict()).team == "red"
    assert failure_side("team_absent", "red") == "team"
    assert failure_side("team_absent", "blue") == "league"  # the stub's absence is not charged
    neither = play_failure(_sim(2.0, [1], ()), ROBOTS, TimingSpec())
    assert neither is not None and neither.failure_class is FailureClass.NOT_PLAYED
    assert "either team" in neither.cause


def test_a_stub_given_a_model_with_other_motor_names_is_said_loudly(
        tmp_path: Path, caplog: pytest.LogCaptureFixture) -> None:
    wolfgang = Path(__file__).resolve().parents[3] / "configs/examples/robots/wolfgang"
    parser = argparse.ArgumentParser()
    add_arguments(parser)
    with caplog.at_level(logging.WARNING):
        write_files(_request(parser, ["--red-model", str(wolfgang)]), tmp_path,
                    stub_image="stub:1")
    warned = [r for r in caplog.records if r.levelno == logging.WARNING]
    assert len(warned) == 1 and warned[0].getMessage().startswith("red robots: the stub robot")
    assert "stands still" in warned[0].getMessage()
    caplog.clear()
    with caplog.at_level(logging.WARNING):  # a robot image of the team's own: its business
        write_files(_request(parser, ["--red-model", str(wolfgang), "--red-image", "team:1"]),
                    tmp_path, stub_image="stub:1")
    assert not caplog.records


def test_compose_says_how_to_collect_results_and_take_it_down_and_collects(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    from hlvs.cli import main

    game = Path(__file__).resolve().parents[3] / "configs/examples/scrimmage_1v1/game.json"
    output = tmp_path / "docker-compose.yml"
    assert main(["compose", str(game), "-o", str(output), "--simulator-image", "sim:x"]) == 0
    printed = capsys.readouterr().out
    assert f"hlvs compose {game} -o {output} --collect" in printed
    assert "docker compose -f docker-compose.yml down" in printed
    assert "docker-compose -f docker-compose.yml down" in printed
    assert "--collect" in output.read_text() and "docker-compose down" in output.read_text()

    sim = _sim(0.0, [], ("red-1", "blue-1")).to_dict()  # FINISHED 0:0 without kick-off
    (tmp_path / "out" / "sim_result.json").write_text(json.dumps({**sim, "match_id": "m"}))
    code = main(["compose", str(game), "-o", str(output), "--collect", "--json"])
    summary = json.loads(capsys.readouterr().out)
    assert code == 1 and summary["status"] == "failed"
    assert summary["failure"].startswith("not_played: the match did not play")
    report = json.loads((tmp_path / "report.json").read_text())
    assert report["failure_class"] == "not_played"
    assert json.loads((tmp_path / "results.json").read_text())["score"] == {"red": 0, "blue": 0}


def test_a_schedule_whose_game_timing_leaves_no_play_is_refused(tmp_path: Path) -> None:
    from orchestrator.config.schedule import load_schedule
    from tests.unit.schedule.test_schedule import COMPRESSED, write_schedule

    fixtures = ("fixtures:\n  round_robin: {teams: [alpha, bravo], first_stream: '+1h', "
                "interval_s: 60}\n")
    short = write_schedule(tmp_path, COMPRESSED + fixtures +
                           "game_defaults:\n  timing: {half_duration_s: 8}\n")
    with pytest.raises(ConfigError) as info:
        load_schedule(short)
    (problem,) = info.value.problems
    assert problem.pointer == "/game_defaults/timing/half_duration_s"
    assert "a half of 8 s leaves 8 s of play" in problem.message
    league = write_schedule(tmp_path, COMPRESSED + fixtures + "game_defaults:\n  timing: "
                            "{half_duration_s: 20}\n")  # with the rules' 45 s READY
    assert load_schedule(league).game_defaults["timing"]["half_duration_s"] == 20
