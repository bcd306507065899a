"""``hlvs match``, ``hlvs scrimmage`` and ``hlvs cleanup``: wire the real engine, host controls,
image resolution and telemetry to :class:`orchestrator.match.MatchRunner`.

Exit codes: 0 the match played to its end, 1 it failed (see report.json), 2 invalid input,
3 infrastructure, 130 interrupted (SIGINT / SIGTERM: everything is stopped and collected first).
"""

from __future__ import annotations

import argparse
import json
import logging
import os
import signal
import sys
import threading
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from types import FrameType
from typing import Any

from orchestrator.config.loader import load_game
from orchestrator.errors import InfrastructureError, OrchestratorError
from orchestrator.match import (
    FailureClass,
    HostControl,
    MatchOutcome,
    MatchPlan,
    MatchRunner,
    RunOptions,
    cleanup,
    local_images,
    plan_from_game,
    scrimmage,
)
from orchestrator.match.runner import ImageResolver

log = logging.getLogger(__name__)


def register(sub: Any) -> None:
    match = sub.add_parser("match", help="play one match from a game.json in Docker containers")
    match.add_argument("game", type=Path, help="game.json (references the two team files)")
    match.add_argument("--out", type=Path, default=None,
                       help="output folder (default: matches/<match_id>)")
    match.add_argument("--grace", type=float, default=None,
                       help="seconds robots get to stop after the game (default: from game.json)")
    match.set_defaults(func=run_match_command)

    scrim = sub.add_parser("scrimmage", help="a short match between two teams of stub robots")
    scrimmage.add_arguments(scrim)
    scrim.set_defaults(func=run_scrimmage_command)

    clean = sub.add_parser("cleanup", help="remove containers, networks and mounts left behind")
    clean.add_argument("--match", default=None, help="only this match id (default: all)")
    clean.set_defaults(func=run_cleanup_command)


@contextmanager
def stop_on_signals() -> Iterator[threading.Event]:
    """SIGINT / SIGTERM set the event (the runner then stops and collects everything)."""
    event = threading.Event()
    owner = os.getpid()

    def handler(signum: int, frame: FrameType | None) -> None:
        if os.getpid() != owner:  # a forked helper (pyroute2's netns worker) inherits this
            os._exit(0)
        log.warning("received %s: stopping the match", signal.Signals(signum).name)
        event.set()

    previous = {s: signal.signal(s, handler) for s in (signal.SIGINT, signal.SIGTERM)}
    try:
        yield event
    finally:
        for sig, old in previous.items():
            signal.signal(sig, old)


def _pull_resolver(client: Any, loaded: Any) -> ImageResolver:
    from orchestrator.pull import resolve_team_images

    def resolve(plan: MatchPlan) -> dict[str, tuple[str | None, str | None]]:
        found: dict[str, tuple[str | None, str | None]] = {}
        for color in ("red", "blue"):
            resolved = resolve_team_images(client, loaded.team(color), limits=loaded.game.limits)
            for number, image in resolved.items():
                key = f"{color}-{number}"
                found[key] = (image.digest or None, str(image.error) if image.error else None)
        for robot in plan.robots:
            found.setdefault(robot.key, (None, "no image named for this player"))
        return found

    return resolve


def play(
    plan: MatchPlan, *, out_dir: Path, pull: bool, loaded: Any = None,
    extra_labels: dict[str, str] | None = None,
) -> MatchOutcome:
    """Play ``plan`` on the local engine with the real host controls, showing progress."""
    from orchestrator.engine import connect
    from orchestrator.engine.containers import DockerRuntime
    from orchestrator.images import project_image
    from orchestrator.telemetry import LiveView, ZenohTelemetry

    client = connect()
    runtime = DockerRuntime(client)
    host = HostControl.for_current_user()
    leftovers = cleanup(runtime, host, match_id=plan.match_id)
    if leftovers.containers or leftovers.networks:
        log.info("removed %d containers and %d networks left by an earlier run of %s",
                 len(leftovers.containers), len(leftovers.networks), plan.match_id)
    simulator_image = project_image("simulator")
    images = _pull_resolver(client, loaded) if pull and loaded is not None else None
    view = LiveView(match_id=plan.match_id)
    with stop_on_signals() as stop_event:
        options = RunOptions(
            out_dir=out_dir, simulator_image=simulator_image, extra_labels=extra_labels or {},
            progress=lambda phase, state: view.update(phase=phase, state=state),
        )
        runner = MatchRunner(
            plan, runtime=runtime, host=host, options=options,
            images=images or local_images(runtime),
            telemetry=lambda endpoint, match_id: ZenohTelemetry(
                endpoint=endpoint, match_id=match_id),
            stop_event=stop_event,
        )
        try:
            outcome = runner.run()
        finally:
            view.close()
    return outcome


def summarize(outcome: MatchOutcome) -> int:
    results = outcome.results
    score = results.get("score") or {}
    if outcome.failure is None:
        forfeit = results.get("forfeit")
        if forfeit:
            what = f"{forfeit['team']} forfeits, winner {forfeit['winner']}"
        else:
            what = (f"red {score.get('red')} - {score.get('blue')} blue, "
                    f"winner {results.get('winner')}")
        print(f"match {outcome.match_id}: {what}; results in {outcome.out_dir}")
        return 0
    failure = outcome.failure
    print(f"match {outcome.match_id} failed ({failure.failure_class.value}): {failure.cause}; "
          f"results in {outcome.out_dir}", file=sys.stderr)
    if failure.failure_class is FailureClass.INTERRUPTED:
        return 130
    if failure.failure_class is FailureClass.INFRASTRUCTURE:
        return InfrastructureError.exit_code
    return 1


def run_match_command(args: argparse.Namespace) -> int:
    loaded = load_game(args.game, images_required=True)
    for warning in loaded.warnings:
        print(f"hlvs: {warning}", file=sys.stderr)
    plan = plan_from_game(loaded, grace_period_s=args.grace)
    out = args.out or Path("matches") / plan.match_id
    return summarize(play(plan, out_dir=out, pull=True, loaded=loaded))


def run_scrimmage_command(args: argparse.Namespace) -> int:
    out: Path = args.out
    game_path = scrimmage.write_files(args, out / "config")
    loaded = load_game(game_path, images_required=True)
    plan = plan_from_game(loaded, grace_period_s=args.grace)
    return summarize(play(plan, out_dir=out, pull=False, loaded=loaded))


def run_cleanup_command(args: argparse.Namespace) -> int:
    from orchestrator.engine import connect
    from orchestrator.engine.containers import DockerRuntime

    host = HostControl.for_current_user()
    report = cleanup(DockerRuntime(connect()), host, match_id=args.match)
    print(json.dumps({
        "containers": list(report.containers), "networks": list(report.networks),
        "host_objects": report.host_objects, "errors": list(report.errors),
    }))
    if report.errors:
        raise OrchestratorError("cleanup incomplete: " + "; ".join(report.errors))
    return 0


__all__ = ["play", "register", "stop_on_signals", "summarize"]
