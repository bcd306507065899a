"""``hlvs bench scrimmage``: is the default scrimmage a game of football?

Plays ``--matches K`` default scrimmages (``hlvs scrimmage`` with no options but the seed: stub
robots in real containers, lockstep stepping), one after the other with seeds ``--seed``,
``--seed + 1``, ... and reads what the referee saw from each ``results.json``. Prints one JSON
document: the fraction of matches in which both halves reached PLAYING, kicks, shots, goals and
own goals per match, falls per robot-minute of simulated time, wall seconds per match (the
whole ``hlvs scrimmage``: start, game, stop and collection; images are built beforehand and not
timed), and whether the targets hold (every match reaches PLAYING in both halves, goals in at
least half of the matches, at most one own goal in ten matches, at most 180 s per match).
``--red-image`` / ``--blue-image`` play a team's robots from another image (as ``hlvs
scrimmage``'s options: a learned kick's image against the stub, say); ``matches_scored``
counts the matches in which each team scored.
"""

from __future__ import annotations

import argparse
import json
import logging
import sys
import tempfile
import threading
import time
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any, TypedDict

from contracts.sim_result import PlayRecord
from orchestrator.errors import OrchestratorError
from orchestrator.paths import user_path

log = logging.getLogger(__name__)

TARGET_WALL_S = 180.0
TARGET_GOAL_FRACTION = 0.5
TARGET_OWN_GOALS_PER_MATCH = 0.1


class MatchFiguresRecord(TypedDict):
    """One match of the benchmark (``per_match``); play counts summed over both teams."""

    seed: int
    match_id: str
    status: str
    score: dict[str, int] | None
    both_halves_playing: bool
    kicks: int | None
    shots: int | None
    goals: int | None
    own_goals: int | None
    falls: int | None
    sim_s: float
    wall_s: float


@dataclass(frozen=True, slots=True, kw_only=True)
class MatchFigures:
    seed: int
    match_id: str
    status: str
    score: dict[str, int] | None
    play: PlayRecord | None
    robots: int
    sim_s: float
    wall_s: float

    def to_json(self) -> MatchFiguresRecord:
        play = self.play
        return {
            "seed": self.seed,
            "match_id": self.match_id,
            "status": self.status,
            "score": self.score,
            "both_halves_playing": play is not None and play.both_halves_playing,
            "kicks": None if play is None else sum(play.kicks.values()),
            "shots": None if play is None else sum(play.shots.values()),
            "goals": None if play is None else sum(play.goals.values()),
            "own_goals": None if play is None else sum(play.own_goals.values()),
            "falls": None if play is None else sum(play.falls.values()),
            "sim_s": round(self.sim_s, 1),
            "wall_s": round(self.wall_s, 1),
        }


def _parse(argv: Sequence[str]) -> argparse.Namespace:
    parser = argparse.ArgumentParser(prog="hlvs bench scrimmage", description=__doc__)
    parser.add_argument("--matches", type=int, default=4, help="scrimmages to play (default 4)")
    parser.add_argument("--seed", type=int, default=1, help="seed of the first scrimmage")
    parser.add_argument("--players", type=int, default=None, choices=(1, 2, 3, 4),
                        help="robots per team (default: the scrimmage's default)")
    parser.add_argument("--keep", type=user_path, default=None,
                        help="keep the match folders here (default: a temporary folder)")
    parser.add_argument("--stepping", choices=("lockstep", "pipelined", "async"),
                        default="lockstep", help="stepping of the scrimmages (default lockstep)")
    parser.add_argument("--class", dest="field_class", choices=("kid", "adult"), default="kid",
                        help="field size and built-in robots (default kid)")
    parser.add_argument("--red-image", default=None,
                        help="image of the red robots (default: the project's stub image)")
    parser.add_argument("--blue-image", default=None,
                        help="image of the blue robots (default: the project's stub image)")
    parser.add_argument("--json", action="store_true", help="print only the JSON document")
    args = parser.parse_args(list(argv))
    if args.matches < 1:
        parser.error("--matches must be at least 1")
    return args


def play_one(*, seed: int, out: Path, players: int | None,
             stop: threading.Event | None = None, stepping: str = "lockstep",
             field_class: str = "kid", red_image: str | None = None,
             blue_image: str | None = None) -> MatchFigures:
    """One default scrimmage with ``seed`` played into ``out`` on the ``field_class`` field
    (a team's robots from ``red_image`` / ``blue_image``, else the stub image); its figures.
    ``stop`` set: the match stops (and is collected) as on SIGINT."""
    from orchestrator import add_scrimmage_arguments as add_arguments
    from orchestrator.config.loader import load_game
    from orchestrator.engine import connect
    from orchestrator.engine.containers import DockerRuntime
    from orchestrator.match import (
        HostControl,
        MatchRunner,
        RunOptions,
        cleanup,
        plan_from_game,
        start_gate,
    )
    from orchestrator.match.scrimmage import ScrimmageRequest, write_files
    from orchestrator.project_images import project_image
    from orchestrator.telemetry import ZenohTelemetry

    scrim = argparse.ArgumentParser()
    add_arguments(scrim)
    match_id = f"bench-scrim-{int(time.time())}-{seed}"
    argv = ["--seed", str(seed), "--match-id", match_id, "--stepping", stepping,
            "--class", field_class]
    if players is not None:
        argv += ["--players", str(players)]
    for option, image in (("--red-image", red_image), ("--blue-image", blue_image)):
        if image is not None:
            argv += [option, image]
    args = scrim.parse_args(argv)
    started = time.monotonic()
    request = ScrimmageRequest.from_options(args)
    plan = plan_from_game(load_game(write_files(request, out / "config")),
                          grace_period_s=args.grace)
    runtime = DockerRuntime(connect())
    host = HostControl.for_current_user()
    runner = MatchRunner(
        plan, runtime=runtime, host=host,
        options=RunOptions(out_dir=out, simulator_image=project_image("simulator"),
                           start_gate=start_gate()),
        telemetry=lambda endpoint, mid: ZenohTelemetry(endpoint=endpoint, match_id=mid),
        stop_event=stop,
    )
    try:
        outcome = runner.run()
    finally:
        cleanup(runtime, host, match_id=match_id)
    wall = time.monotonic() - started
    results = outcome.results
    assert results is not None  # a match run here always writes its results
    return MatchFigures(
        seed=seed, match_id=match_id, status=results.status, score=results.score,
        play=results.play, robots=len(results.robots),
        sim_s=(results.sim_time_ms or 0) / 1000.0, wall_s=wall,
    )


def summarize(matches: list[MatchFigures]) -> dict[str, Any]:
    count = len(matches)
    played = [m.play for m in matches if m.play is not None]
    both = sum(1 for p in played if p.both_halves_playing)
    with_goals = sum(1 for p in played if sum(p.goals.values()) > 0)
    own_goals = sum(sum(p.own_goals.values()) for p in played)
    robot_minutes = sum(m.robots * m.sim_s / 60.0 for m in matches if m.play is not None)
    walls = [m.wall_s for m in matches]

    def per_match(total: float) -> float:
        return round(total / count, 2)

    return {
        "bench": "scrimmage",
        "matches": count,
        "successful": sum(1 for m in matches if m.status == "success"),
        "both_halves_playing_fraction": round(both / count, 3),
        "kicks_per_match": per_match(sum(sum(p.kicks.values()) for p in played)),
        "shots_per_match": per_match(sum(sum(p.shots.values()) for p in played)),
        "goals_per_match": per_match(sum(sum(p.goals.values()) for p in played)),
        "matches_with_goals_fraction": round(with_goals / count, 3),
        "matches_scored": {
            team: sum(1 for m in matches if m.score is not None and m.score.get(team, 0) > 0)
            for team in ("red", "blue")
        },
        "own_goals": own_goals,
        "own_goals_per_match": per_match(own_goals),
        "falls_per_robot_minute": round(
            sum(sum(p.falls.values()) for p in played) / robot_minutes, 3
        ) if robot_minutes else None,
        "wall_s_per_match": round(sum(walls) / count, 1),
        "wall_s_max": round(max(walls), 1),
        "targets": {
            "all_both_halves_playing": both == count,
            "goals_in_half_the_matches": with_goals >= TARGET_GOAL_FRACTION * count,
            "own_goals_at_most_1_in_10": own_goals <= TARGET_OWN_GOALS_PER_MATCH * count,
            "wall_s_at_most_180": max(walls) <= TARGET_WALL_S,
        },
        "per_match": [m.to_json() for m in matches],
    }


def run(*, matches: int, seed: int, players: int | None, folder: Path,
        quiet: bool, stepping: str = "lockstep", field_class: str = "kid",
        red_image: str | None = None, blue_image: str | None = None) -> dict[str, Any]:
    """Play the scrimmages; SIGINT / SIGTERM stop the one playing and skip the rest (the
    summary covers the matches played so far, the interrupted one included)."""
    from orchestrator import stop_on_signals

    figures = []
    with stop_on_signals() as stop:
        for i in range(matches):
            figure = play_one(seed=seed + i, out=folder / f"match-{i + 1}", players=players,
                              stop=stop, stepping=stepping, field_class=field_class,
                              red_image=red_image, blue_image=blue_image)
            figures.append(figure)
            if not quiet:
                print(json.dumps(figure.to_json()), file=sys.stderr)
            if stop.is_set():
                break
    result = summarize(figures)
    result["interrupted"] = len(figures) < matches or stop.is_set()
    result["stepping"] = stepping
    result["field_class"] = field_class
    result["images"] = {"red": red_image, "blue": blue_image}
    return result


def main(argv: Sequence[str]) -> int:
    args = _parse(argv)
    try:
        if args.keep is not None:
            result = run(matches=args.matches, seed=args.seed, players=args.players,
                         folder=args.keep, quiet=args.json, stepping=args.stepping,
                         field_class=args.field_class, red_image=args.red_image,
                         blue_image=args.blue_image)
        else:
            with tempfile.TemporaryDirectory(prefix="hlvs-bench-scrimmage-") as folder:
                result = run(matches=args.matches, seed=args.seed, players=args.players,
                             folder=Path(folder), quiet=args.json, stepping=args.stepping,
                             field_class=args.field_class, red_image=args.red_image,
                             blue_image=args.blue_image)
    except OrchestratorError as exc:
        print(json.dumps({"bench": "scrimmage", "error": str(exc)}))
        return exc.exit_code
    print(json.dumps(result))
    return 0 if result["successful"] == result["matches"] else 1


__all__ = ["MatchFigures", "main", "play_one", "summarize"]
