"""``hlvs bench report``: the matrix in one JSON document (small sizes, no Docker kinds)."""

from __future__ import annotations

import json
import os
import subprocess
import sys

import pytest

from testkit.figures import (
    FLOOD_TARGET,
    LEAGUE_MATCH_SIM_S,
    LEAGUE_MATCH_WAITS_S,
    Target,
    cpu_times,
    judged,
    league_match_figures,
    machine_target,
    report_rounds,
)
from testkit.figures import median_figures as _median


def test_report_runs_the_kinds_and_judges_medians_against_targets() -> None:
    proc = subprocess.run(
        [sys.executable, "-m", "hlvs", "bench", "report", "--only", "sim,pipelined",
         "--repeats", "2", "--robots", "2", "--sim-seconds", "0.25", "--world-seconds", "0.5",
         "--json"],
        capture_output=True, text=True, timeout=300,
    )  # fmt: skip
    assert proc.returncode == 0, proc.stderr[-2000:]
    lines = proc.stdout.strip().splitlines()
    assert len(lines) == 1  # one JSON document and nothing else on stdout
    report = json.loads(lines[0])
    assert report["bench"] == "report" and report["errors"] == 0
    assert len(report["load_average_before"]) == 3
    shares = [report["steal_share"], *(r["steal_share"] for r in report["sim"]["runs"])]
    assert all(isinstance(x, float) and 0.0 <= x < 1.0 for x in shares), shares
    assert "async" not in report and "bringup" not in report
    assert report["bringup_repeats"] == 2  # as many bring-ups as --repeats unless told
    sim, pipelined = report["sim"], report["pipelined"]
    assert len(sim["runs"]) == 2 and len(pipelined["runs"]) == 2
    assert sim["target"] == {"figure": "ratio", "min": 0.95}
    assert sim["meets_target"] == (sim["median"]["ratio"] >= 0.95)
    ratio = pipelined["median"]["ratio_interleaved"]
    assert ratio > 0 and pipelined["meets_target"] == (ratio >= 0.92)
    bare = sim["median"]["bare_real_time_factor"]
    assert report["bare_real_time_factor"] == bare > 0
    assert report["reference_bare_real_time_factor"] == 12.0
    assert 0 <= pipelined["median"]["client_wait_share"] < 1
    # this machine has a C compiler (make setup installs one): the compiled clients ran
    assert all(run["native_clients"] is True for run in pipelined["runs"])
    # the step beside a busy clients' CPU over an idle one, each run (None on one CPU)
    neighbours = [run["neighbour_ratio"] for run in pipelined["runs"]]
    if len(os.sched_getaffinity(0)) >= 2:
        assert all(isinstance(x, float) and 0.5 < x < 3 for x in neighbours), neighbours
        shared = sum(1 for x in neighbours if x >= 1.15)
        assert pipelined["shared_core_runs"] == shared and "shared_core_runs" not in sim
    else:
        assert neighbours == [None, None]


def test_steal_share_is_the_stolen_part_of_the_cpus_ticks_between_two_readings() -> None:
    from testkit.figures import steal_share

    before = cpu_times("cpu  100 0 50 800 10 0 5 35 0 0\ncpu0 50 0 25 400 5 0 2 18 0 0\n")
    after = cpu_times("intr 1\ncpu  160 0 70 900 10 0 5 55 7 0\n")
    assert before == (35, 1000) and after == (55, 1200)
    assert steal_share(before, after) == 0.1  # 20 of 200 ticks
    assert cpu_times("intr 1\n") is None
    assert steal_share(None, after) is None and steal_share(after, after) is None


def test_report_runs_lockstep_with_clients_written_like_the_leagues() -> None:
    """``lockstep_league``: a lockstep run whose clients write each request's length and body
    in two writes without ``TCP_NODELAY``, judged against the lockstep target (shape only: the
    figures of two robots for a quarter of a second say nothing of the speed)."""
    proc = subprocess.run(
        [sys.executable, "-m", "hlvs", "bench", "report", "--only", "lockstep_league",
         "--repeats", "1", "--robots", "2", "--sim-seconds", "0.25", "--json"],
        capture_output=True, text=True, timeout=300,
    )  # fmt: skip
    assert proc.returncode == 0, proc.stderr[-2000:]
    report = json.loads(proc.stdout)
    assert report["errors"] == 0 and "lockstep" not in report and "sim" not in report
    league = report["lockstep_league"]
    assert league["target"] == {"figure": "ratio_interleaved", "min": 0.85}
    [run] = league["runs"]
    median = league["median"]
    for key in ("ratio_interleaved", "requests_per_s", "client_answer_p50_ms",
                "client_round_trip_p50_ms", "round_trip_p50_ms", "client_wait_share"):
        assert isinstance(run[key], float) and run[key] > 0, key
        assert median[key] == run[key], key
    assert league["meets_target"] == (median["ratio_interleaved"] >= 0.85)
    assert run["native_clients"] is True  # compiled, as the league's own client is
    assert 0 < run["floor_ratio"] <= 1 and run["of_floor"] > 0  # the floor beside it


def test_a_judged_figure_names_its_target() -> None:
    assert judged(Target("ratio", minimum=0.85), {"ratio": 0.84}) == {
        "target": {"figure": "ratio", "min": 0.85}, "meets_target": False}
    assert judged(Target("s", maximum=3.0), {"s": 2.5})["meets_target"] is True
    assert judged(FLOOD_TARGET, {"ratio_interleaved": None}) == {
        "target": {"figure": "ratio_interleaved", "min": 0.8}, "meets_target": None}


def test_bad_kind_is_named() -> None:
    proc = subprocess.run(
        [sys.executable, "-m", "hlvs", "bench", "report", "--only", "sim,gpu"],
        capture_output=True, text=True, timeout=60,
    )  # fmt: skip
    assert proc.returncode == 2 and "--only: unknown kind(s) gpu" in proc.stderr


def test_median_skips_failed_runs_and_targets_have_a_bound() -> None:
    runs = [{"ratio": 0.9, "note": "x"}, {"error": "exit code 3"}, {"ratio": 0.7}, {"ratio": 1.0}]
    assert _median(runs) == {"ratio": 0.9}
    assert Target("bringup_s", maximum=5.0).met(4.9) and not Target("s", maximum=5.0).met(5.1)
    assert not Target("ratio", minimum=0.9).met(0.89)


def test_targets_are_the_performance_goals_and_scale_with_the_machine() -> None:
    """The report's targets are the goals (lockstep 0.85, async and pipelined 0.92, sim 0.95,
    cameras 1.0 x real time and bring-up 3 s on a machine whose bare loop runs 12x real time),
    so that a run that misses a goal cannot print ``meets_target: true``."""
    assert machine_target("lockstep", 6.0) == Target("ratio_interleaved", minimum=0.85)
    assert machine_target("lockstep_league", 6.0) == Target("ratio_interleaved", minimum=0.85)
    assert machine_target("async", None) == Target("ratio_interleaved", minimum=0.92)
    assert machine_target("pipelined", 30.0) == Target("ratio_interleaved", minimum=0.92)
    assert machine_target("sim", 6.0) == Target("ratio", minimum=0.95)
    assert not machine_target("lockstep", 12.0).met(0.749)  # type: ignore[union-attr]
    # cameras: the minimum moves with the machine's speed, the bring-up's maximum against it
    assert machine_target("cameras", 12.0) == Target("real_time_factor", minimum=1.0)
    assert machine_target("cameras", 6.0) == Target("real_time_factor", minimum=0.5)
    assert machine_target("cameras", None) == Target("real_time_factor", minimum=1.0)
    assert machine_target("bringup", 12.0) == Target("bringup_s", maximum=3.0)
    assert machine_target("bringup", 4.0) == Target("bringup_s", maximum=9.0)
    assert not machine_target("bringup", 12.0).met(3.35)  # type: ignore[union-attr]


def test_a_league_match_is_costed_from_a_short_one_at_the_leagues_pace() -> None:
    """The ``match`` kind's figures: a league match (two 600 s halves after 45 s READYs and 5 s
    SETs, 1300 s simulated, and 135 s of the referee's wall waits) paced to real time at most."""
    assert (LEAGUE_MATCH_SIM_S, LEAGUE_MATCH_WAITS_S) == (1300.0, 135.0)
    slow = league_match_figures(0.25, 30.0, 2)  # a quarter of real time on two CPUs
    assert slow == {"wall_s_per_sim_minute": 240.0, "league_match_wall_s": 5365.0,
                    "matches_per_core_hour": 0.336}
    fast = league_match_figures(4.0, 10.0, 16)  # faster than real time: held to it
    assert fast["league_match_wall_s"] == 1445.0 and fast["wall_s_per_sim_minute"] == 15.0
    assert fast["matches_per_core_hour"] == round(3600 / (1445.0 * 16), 3)
    for bad in ((0.0, 10.0, 2), (1.0, 10.0, 0)):
        with pytest.raises(ValueError, match="expected a real-time factor above 0"):
            league_match_figures(*bad)


def test_every_kind_gets_its_own_number_of_runs_interleaved() -> None:
    """``--match-repeats`` and ``--bringup-repeats`` above ``--repeats`` are all run (the
    rounds once stopped at ``--repeats``: ``--repeats 1 --match-repeats 3`` played one match)."""
    kinds = ["sim", "bringup", "match"]
    assert report_rounds(kinds, {"sim": 1, "bringup": 2, "match": 3}) == [
        ["sim", "bringup", "match"], ["bringup", "match"], ["match"]]
    assert report_rounds(kinds, {"sim": 2, "bringup": 2, "match": 1}) == [
        ["sim", "bringup", "match"], ["sim", "bringup"]]
    assert report_rounds(["sim"], {"sim": 0}) == [["sim"]]  # at least one run
    assert report_rounds([], {}) == []
