"""build_results: the simulator's result, the robots' records and a forfeit into results.json."""

from __future__ import annotations

import json

from contracts.match_results import Forfeit, MatchLimits, MatchResults, RobotResult
from contracts.sim_result import SimResult, SpoofingAttempt, SpoofingRecord
from orchestrator.match.results import RobotRecord, build_results

LIMITS = MatchLimits(cpus=4.0, memory_gb=16.0, pids=1024, log_folder_gb=10.0,
                     team_api_mb_s=350.0, team_comm_mb_s=1.0, grace_period_s=5.0,
                     allow_internet=False, host_controls=None)


def _attempt(sender: str | None, count: int) -> SpoofingAttempt:
    return SpoofingAttempt(channel="api", sender="10.0.1.11", sender_robot=sender,
                           claimed="blue-1", message="connect", count=count)


def test_spoofing_is_counted_per_sending_robot() -> None:
    sim = SimResult(
        match_id="m", seed=1, state="FINISHED", score={"red": 1, "blue": 0}, winner="red",
        robots={"red-1": {"connects": 1}, "blue-1": {"connects": 1}},
        spoofing=SpoofingRecord(total=7, attempts=(_attempt("red-1", 5), _attempt("red-1", 1),
                                                   _attempt(None, 1))),
    )  # fmt: skip
    robots = [RobotRecord(key=k, color=k[:-2], number=1,
                          entry=RobotResult(image="i", container=f"c-{k}"))
              for k in ("red-1", "blue-1")]
    results = build_results(match_id="m", seed=1, sim_result=sim, robots=robots, forfeit=None,
                            limits=LIMITS, versions={}, timings_s={}, failure=None)
    assert results.robots["red-1"].spoofing_attempts == 6
    assert results.robots["blue-1"].spoofing_attempts == 0
    assert results.robots["red-1"].api == {"connects": 1}
    assert results.warnings == ()
    again = MatchResults.from_json(results.to_json())
    assert again == results and json.loads(results.to_json())["spoofing"]["total"] == 7


def test_a_forfeit_sets_score_and_winner_without_a_simulator() -> None:
    forfeit = Forfeit(team="blue", winner="red", reason="no usable image",
                      score={"red": 0, "blue": 0})
    robots = [RobotRecord(key="blue-1", color="blue", number=1,
                          entry=RobotResult(image="b", image_error="image b not found"))]
    results = build_results(match_id="m", seed=1, sim_result=None, robots=robots,
                            forfeit=forfeit, limits=LIMITS, versions={"hlvs-runner": "1"},
                            timings_s={"pulling": 0.1}, failure=None)
    assert (results.score, results.winner, results.final_state) == (forfeit.score, "red", None)
    assert results.versions == {"hlvs-runner": "1", "simulator": None}
    assert results.robots["blue-1"].image_error == "image b not found"


def test_the_shootout_goals_are_kept_apart_from_the_match_goals() -> None:
    """The GameController's score counts the shoot-out's goals (a 0-0 decided 3-2 on
    penalties ends 3-2); results.json keeps the match's 0-0 and the shoot-out's 3-2 apart."""
    sim = SimResult(match_id="m", seed=1, state="FINISHED", score={"red": 4, "blue": 3},
                    winner="red", shootout={"red": {"kicks": 5, "scored": 3},
                                            "blue": {"kicks": 5, "scored": 2}}, coin_toss=False)
    results = build_results(match_id="m", seed=1, sim_result=sim, robots=[], forfeit=None,
                            limits=LIMITS, versions={}, timings_s={}, failure=None)
    assert (results.score, results.shootout, results.winner) == (
        {"red": 1, "blue": 1}, {"red": 3, "blue": 2}, "red")
    data = json.loads(results.to_json())
    assert data["score"] == {"red": 1, "blue": 1} and data["shootout"] == {"red": 3, "blue": 2}
    assert MatchResults.from_json(results.to_json()) == results
    plain = build_results(match_id="m", seed=1, sim_result=SimResult(
        match_id="m", seed=1, state="FINISHED", score={"red": 2, "blue": 0}, winner="red"),
        robots=[], forfeit=None, limits=LIMITS, versions={}, timings_s={}, failure=None)
    assert plain.shootout is None and "shootout" not in json.loads(plain.to_json())
