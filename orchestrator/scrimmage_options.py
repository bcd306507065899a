"""The command-line options of a scrimmage (``hlvs scrimmage``, and the benchmarks that play
one: ``hlvs bench bringup``, ``hog``, ``scrimmage``), parsed into a
:class:`orchestrator.match.ScrimmageRequest`; standard library only, so that ``hlvs --help``
does not import the match machinery."""

from __future__ import annotations

import argparse

from contracts import ADULT_SCRIMMAGE, MIN_PLAYING_S, SCRIMMAGE
from orchestrator.paths import user_path


def _model(text: str) -> str:
    """A model package path made absolute (the team files are written elsewhere); built-in
    names as they are."""
    return text if text in ("adult-default", "kid-default") else str(user_path(text))


def add_scrimmage_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--out", type=user_path, default="matches/scrimmage",
                        help="output folder (default: matches/scrimmage)")
    parser.add_argument("--red-image", default=None,
                        help="image of the red robots (default: the project's stub image)")
    parser.add_argument("--blue-image", default=None,
                        help="image of the blue robots (default: the project's stub image)")
    parser.add_argument("--red-model", default=None, type=_model,
                        help="robot model of every red robot: a built-in name (kid-default) or "
                        "a robot model package folder (default: kid-default)")
    parser.add_argument("--blue-model", default=None, type=_model,
                        help="robot model of every blue robot (as --red-model)")
    parser.add_argument("--class", dest="field_class", choices=("kid", "adult"), default=None,
                        help="field size: kid (9 x 6 m, up to 4 players) or adult (14 x 9 m, up "
                             "to 3); default: adult when a team plays adult-default, else kid")
    parser.add_argument("--players", type=int, default=1, choices=(1, 2, 3, 4),
                        help="robots per team: a striker, then a goalie, then defenders "
                             "(default 1; at most 3 on the adult field)")
    parser.add_argument("--half-duration", type=float, default=None,
                        help="simulated seconds of game clock per half; READY and SET before the "
                        "half's kick-off stop the clock (default "
                        f"{SCRIMMAGE.half_duration_s:g}, {ADULT_SCRIMMAGE.half_duration_s:g} on "
                        f"the adult field; at least {MIN_PLAYING_S:g}: each half keeps "
                        f"{MIN_PLAYING_S:g} s of play)")
    parser.add_argument("--ready-duration", type=float, default=None,
                        help="simulated seconds of READY in this scrimmage (default "
                        f"{SCRIMMAGE.ready_duration_s:g}, {ADULT_SCRIMMAGE.ready_duration_s:g} on "
                        "the adult field; the clock stands still in READY before each half's "
                        "kick-off, so it does not shorten the half; matches: 45)")
    parser.add_argument("--minimum-play", type=float, default=MIN_PLAYING_S,
                        help="simulated seconds of PLAYING each half keeps and the match must "
                        f"play to count (default {MIN_PLAYING_S:g}); 0: a match not meant to "
                        "play football (a quick test of containers, logs or signals)")
    parser.add_argument("--wait-before-ready", type=float,
                        default=SCRIMMAGE.wait_before_first_ready_s,
                        help="wall seconds between robot start and the first READY (default "
                        f"{SCRIMMAGE.wait_before_first_ready_s:g})")
    parser.add_argument("--grace", type=float, default=SCRIMMAGE.grace_period_s,
                        help="seconds robots get to stop after the game (default 5)")
    parser.add_argument("--robot-command", default=None,
                        help="dockerCmd of every robot (default: goalie / striker for the stub)")
    parser.add_argument("--match-id", default=None,
                        help="match id (default: scrimmage-<random>)")
    parser.add_argument("--stepping", choices=("lockstep", "pipelined", "async"),
                        default="lockstep",
                        help="lockstep (default): each step waits for the robots; pipelined: "
                        "they think while the next step runs (one step more latency); async: "
                        "the simulation never waits (HLVS), paced to real time")
    parser.add_argument("--seed", type=int, default=42,
                        help="seed of the simulation and the referee (default 42)")
    parser.add_argument("--stub", action="store_true",
                        help="accepted for compatibility: stub robots are the default")
    add_gpu_argument(parser, default="auto")


def add_gpu_argument(parser: argparse.ArgumentParser, *, default: str | None) -> None:
    """``--gpu auto|on|off``: the host's NVIDIA GPU for the robot cameras (``gpu`` of
    game.json)."""
    parser.add_argument("--gpu", choices=("auto", "on", "off"), default=default,
                        help="robot cameras on the host's NVIDIA GPU: auto uses it when Docker "
                        "can, else the CPU; on requires it; off: the CPU (default: "
                        + (default or "gpu of game.json, else auto") + ")")


__all__ = ["add_gpu_argument", "add_scrimmage_arguments"]
