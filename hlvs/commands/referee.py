"""``hlvs referee test PATH...``: the league's referee test scenarios against our referee.

Each ``test_scenario.json`` (hlvs_webots ``controllers/referee/tests/**``; a folder is searched
for them) is played with the ``game.json`` beside it and the team files that names, in the
MuJoCo world with our referee on simulated time (:mod:`simulator.league_tests`). A line per
failed test names the file, the step, the test and the expectation; ``--json`` prints one JSON
object. Exit 0 when every test passes, 1 when one fails, 2 on invalid input (a scenario, a
game or a team file that cannot be read: nothing is played).
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path
from typing import TYPE_CHECKING, Any

from orchestrator import ConfigError, ExitCode, user_path

if TYPE_CHECKING:
    from contracts import MatchSpec, RobotId
    from referee import LeagueScenario
    from simulator import LeagueOutcome

SCENARIO_FILE = "test_scenario.json"
GAME_FILE = "game.json"


def register(sub: Any) -> None:
    parser: argparse.ArgumentParser = sub.add_parser(
        "referee", help="tools for the referee: play the league's referee test scenarios"
    )
    inner = parser.add_subparsers(dest="referee_command", metavar="COMMAND", title="commands")
    inner.required = True
    test: argparse.ArgumentParser = inner.add_parser(
        "test",
        help="play the league's referee test scenarios (test_scenario.json) against our referee",
        description=(
            "Play each test_scenario.json of the league's referee test suite (hlvs_webots "
            "controllers/referee/tests), with the game.json beside it, against our referee in "
            "the MuJoCo world, as the league's test supervisor plays it in Webots."
        ),
        epilog="exit codes: 0 every test passed, 1 a test failed, 2 invalid input",
    )
    test.add_argument(
        "paths", nargs="+", type=user_path, metavar="PATH",
        help="test_scenario.json files, or folders searched for them",
    )  # fmt: skip
    test.add_argument("--json", action="store_true", help="print one JSON object")
    test.add_argument(
        "--max-sim-s", type=float, default=3600.0,
        help="stop a scenario after this many simulated seconds (default 3600)",
    )  # fmt: skip
    test.add_argument(
        "--world", choices=("league", "match"), default="league",
        help="league: the league's test robot the scenarios push the ball and robots into (its "
        "crouched Darwin-OP's body; default); match: our robots; matches never use the league's",
    )  # fmt: skip
    test.add_argument(
        "--ball", choices=("league", "match"), default="league",
        help="league: the league's ball as Webots simulates it (0.0791 kg, its proto's scale "
        "cubed times 0.205 kg; 77 %% of its speed lost a second; no rolling friction; "
        "default); match: the match ball",
    )  # fmt: skip
    test.add_argument(
        "--contacts", choices=("ode", "spring"), default="ode",
        help="ode: the ball's contacts as ODE makes the league's (its soft grass takes a dropped "
        "ball dead, restitution 0.74 off the robots, friction 0.5 on the grass and 1 on the "
        "robots, no rolling friction; default); spring: a spring and damper that bounce it at "
        "0.76 in the league world",
    )  # fmt: skip
    test.set_defaults(func=_test)


def find_scenarios(paths: list[Path]) -> tuple[list[Path], list[str]]:
    """The scenario files named or found under the folders named; problems for paths that name
    none."""
    found: list[Path] = []
    problems = []
    for path in paths:
        if path.is_dir():
            inside = sorted(path.rglob(SCENARIO_FILE))
            if not inside:
                problems.append(f"{path}: no {SCENARIO_FILE} in this folder")
            found.extend(inside)
        elif path.is_file():
            found.append(path)
        else:
            problems.append(f"{path}: no such file or folder")
    return list(dict.fromkeys(found)), problems


def _team_config(raw: object, game_path: Path) -> object:
    """A team ``config`` of a league game.json made absolute: relative to game.json's folder,
    else to a folder above it (the league's are relative to ``controllers/referee``, where its
    referee runs), else the file of that name beside game.json."""
    if not isinstance(raw, str) or Path(raw).is_absolute():
        return raw
    for base in (game_path.parent, *game_path.parent.parents):
        if (base / raw).is_file():
            return str(base / raw)
    beside = game_path.parent / Path(raw).name
    return str(beside) if beside.is_file() else raw


def load_match(game_path: Path) -> tuple[MatchSpec, dict[RobotId, float]]:
    """The match spec of a league game.json and, per robot, its standing height in the league's
    world (its team file's ``halfTimeStartingPose`` z). Raises ConfigError.

    A test scenario is not a match meant to play football: unless the file says otherwise its
    ``timing.minimum_play_s`` is 0, so a game the league plays with short halves (its knockout
    test has 20 s halves and the 45 s READY) is not refused for want of play."""
    from contracts import RobotId, TeamColor
    from orchestrator.config import parse_game, parse_json, read_text, to_match_spec

    document = parse_json(read_text(game_path), file=str(game_path))
    if isinstance(document, dict):
        timing = document.setdefault("timing", {})
        if isinstance(timing, dict):
            timing.setdefault("minimum_play_s", 0)
        for color in ("red", "blue"):
            team = document.get(color)
            if isinstance(team, dict) and "config" in team:
                team["config"] = _team_config(team["config"], game_path)
    loaded = parse_game(document, source=game_path)
    spec = to_match_spec(loaded, robot_addresses={}, telemetry_listen=None)
    heights = {
        RobotId(TeamColor(color), player.number): float(player.half_time_pose.translation[2])
        for color in ("red", "blue")
        for player in loaded.team(color).players
    }
    return spec, heights


def _errors(exc: ConfigError) -> list[str]:
    return [str(p) for p in exc.problems if p.severity != "warning"] or [str(exc)]


def _prepare(
    files: list[Path],
) -> tuple[list[tuple[LeagueScenario, MatchSpec, dict[RobotId, float]]], list[str]]:
    from referee import ScenarioError, load_league_scenario

    ready, problems = [], []
    for path in files:
        try:
            scenario = load_league_scenario(path)
        except ScenarioError as exc:
            problems.append(str(exc))
            continue
        game = path.parent / GAME_FILE
        if not game.is_file():
            problems.append(f"{path}: no {GAME_FILE} beside it ({game})")
            continue
        try:
            spec, heights = load_match(game)
        except ConfigError as exc:
            problems.extend(_errors(exc))
            continue
        ready.append((scenario, spec, heights))
    return ready, problems


def failure_lines(outcome: LeagueOutcome) -> list[str]:
    """One line per test that did not pass: file, step, test, expectation."""
    lines: list[str] = []
    for test in outcome.tests:
        head = f"{outcome.path}: step {test.step} ({test.pointer}) {test.name!r}"
        if test.critical:
            head += " [critical]"
        if test.status == "fail":
            lines.extend(f"{head}: {failure}" for failure in test.failures)
        elif test.status == "skip":
            why = (
                "after a critical failure" if outcome.ending == "critical"
                else f"its step never ended ({outcome.ending})"
            )  # fmt: skip
            lines.append(f"{head}: not run to its end: {why}")
    return lines


def _summary(outcomes: list[LeagueOutcome], wall_s: float) -> dict[str, Any]:
    return {
        "files": len(outcomes),
        "files_passed": sum(o.ok for o in outcomes),
        "tests": sum(len(o.tests) for o in outcomes),
        "tests_passed": sum(o.passed for o in outcomes),
        "wall_s": round(wall_s, 1),
    }


def _test(args: argparse.Namespace) -> int:
    from simulator import run_league_scenario

    started = time.perf_counter()
    files, problems = find_scenarios(list(args.paths))
    ready, invalid = _prepare(files)
    problems += invalid
    if problems:
        for problem in problems:
            print(f"hlvs referee test: {problem}", file=sys.stderr)
        if args.json:
            print(json.dumps({"ok": False, "invalid": problems}))
        return ExitCode.INVALID
    outcomes = []
    for scenario, spec, heights in ready:
        outcome = run_league_scenario(
            spec,
            scenario,
            league_standing_z=heights,
            max_sim_s=args.max_sim_s,
            ball=args.ball,
            world=args.world,
            contacts=args.contacts,
        )
        outcomes.append(outcome)
        if not args.json:
            verdict = "PASS" if outcome.ok else "FAIL"
            print(
                f"{verdict} {outcome.passed}/{len(outcome.tests)} {outcome.path} "
                f"(simulated {outcome.sim_time_s:.1f} s, wall {outcome.wall_s:.1f} s, "
                f"{outcome.ending})"
            )
            for line in failure_lines(outcome):
                print(f"  {line}")
            for test in outcome.tests:
                if test.ignored:
                    keys = ", ".join(test.ignored)
                    print(f"  note: {outcome.path}: {test.pointer} {test.name!r}: not checked, "
                          f"as the league's runner does not: {keys}")  # fmt: skip
            sys.stdout.flush()
    summary = _summary(outcomes, time.perf_counter() - started)
    ok = all(o.ok for o in outcomes)
    if args.json:
        print(json.dumps({"ok": ok, **summary, "scenarios": [o.to_json() for o in outcomes]}))
    else:
        print(
            f"{summary['files_passed']}/{summary['files']} files passed, "
            f"{summary['tests_passed']}/{summary['tests']} tests, {summary['wall_s']} s"
        )
    return ExitCode.OK if ok else ExitCode.FAILED
