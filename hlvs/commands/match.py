"""``hlvs match``, ``hlvs scrimmage`` and ``hlvs cleanup``: the parsers; the work is in
:mod:`hlvs.commands.play`, imported only when a command runs.

Exit codes: 0 the match played to its end, 1 it failed (see report.json), 2 invalid input,
3 infrastructure, 4 decided by forfeit, 130 interrupted (SIGINT / SIGTERM: everything is stopped
and collected first).
"""

from __future__ import annotations

import argparse
import logging
from typing import Any

from orchestrator import add_gpu_argument, add_scrimmage_arguments, user_path

MATCH_EPILOG = (
    "exit codes: 0 the match played to its end, 1 it failed (see report.json), 2 invalid input, "
    "3 infrastructure, 4 decided by forfeit, 130 interrupted"
)


def register(sub: Any) -> None:
    match = sub.add_parser(
        "match", help="play one match from a game.json in Docker containers", epilog=MATCH_EPILOG
    )
    match.add_argument("game", type=user_path, help="game.json (references the two team files)")
    match.add_argument("--out", type=user_path, default=None,
                       help="output folder (default: matches/<match_id>)")
    match.add_argument("--grace", type=float, default=None,
                       help="seconds robots get to stop after the game (default: from game.json)")
    match.add_argument("--json", action="store_true",
                       help="print results.json (with the outcome and output folder) on stdout")
    add_gpu_argument(match, default=None)
    add_pool_arguments(match)
    match.set_defaults(func=run_match_command, log_level=logging.INFO)

    scrim = sub.add_parser(
        "scrimmage", help="a short match between two teams of stub robots", epilog=MATCH_EPILOG
    )
    add_scrimmage_arguments(scrim)
    scrim.add_argument("--json", action="store_true",
                       help="print results.json (with the outcome and output folder) on stdout")
    add_pool_arguments(scrim)
    scrim.set_defaults(func=run_scrimmage_command, log_level=logging.INFO)

    clean = sub.add_parser(
        "cleanup", help="salvage the logs of matches whose orchestrator is gone, then remove "
        "their containers, networks and mounts")
    clean.add_argument("--match", default=None,
                       help="only this match id, refused while its orchestrator runs (default: "
                       "every match whose orchestrator is gone)")
    clean.add_argument("--dry-run", action="store_true",
                       help="list what would be removed, remove nothing")
    clean.set_defaults(func=run_cleanup_command)


def add_pool_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--pool", choices=("local", "slurm"), default="local",
                        help="where the match runs: this host's Docker engine (local, default) "
                        "or a Slurm job on a whole node of the cluster (slurm)")
    parser.add_argument("--slurm-conf", default=None,
                        help="the cluster's slurm.conf with --pool slurm (default: $SLURM_CONF "
                        "or the one 'hlvs pool up' writes)")
    parser.add_argument("--placement", choices=("dense", "league"), default="dense",
                        help="with --pool slurm: the whole match on one node (dense, default) "
                        "or the simulator on a node and each robot on a node of its own "
                        "(league: one heterogeneous job, robots with their node's network)")
    parser.add_argument("--league-nodes", default=None, metavar="NAME=ADDR,...",
                        help="league placement inside its job: the simulator's node, then one "
                        "node per robot (red 1..n, blue 1..n), as the Slurm job passes them")
    parser.add_argument("--node-netns", default=None, metavar="PATH",
                        help="league placement on nodes that share this Docker engine: each "
                        "node's network namespace, e.g. /run/netns/hlvs-{node}")
    parser.add_argument("--account", default=None,
                        help="Slurm account the match is charged to with --pool slurm (a "
                        "team's: its quota applies; default: the user's default account)")


def run_match_command(args: argparse.Namespace) -> int:
    from hlvs.commands import play

    return play.run_match_command(args)


def run_scrimmage_command(args: argparse.Namespace) -> int:
    from hlvs.commands import play

    return play.run_scrimmage_command(args)


def run_cleanup_command(args: argparse.Namespace) -> int:
    from hlvs.commands import play

    return play.run_cleanup_command(args)


def __getattr__(name: str) -> Any:  # play, summarize, stop_on_signals: kept importable from here
    if name in ("play", "summarize", "stop_on_signals"):
        from hlvs.commands import play

        return getattr(play, name)
    raise AttributeError(name)


__all__ = [
    "add_pool_arguments", "register", "run_cleanup_command", "run_match_command",
    "run_scrimmage_command",
]
