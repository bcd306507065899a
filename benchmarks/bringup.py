"""``hlvs bench bringup``: seconds from the start of a match to every robot connected.

Starts a scrimmage of stub robots (images cached; building them is not timed), measures from the
moment the runner enters STARTING (networks, simulator, holders, bandwidth limits, robots) until
the simulator's telemetry lists every robot as connected, then stops the match. Prints one JSON
line: ``{"bench": "bringup", "robots": 8, "bringup_s": ..., "containers_s": ..., "phases_s":
{...}, "robot_steps_max_s": {...}, "after_containers_s": ..., ...}``.
"""

from __future__ import annotations

import argparse
import json
import logging
import queue
import tempfile
import threading
import time
from collections.abc import Sequence
from pathlib import Path

from orchestrator.errors import OrchestratorError
from orchestrator.paths import user_path

log = logging.getLogger(__name__)

TARGET_S = 10.0


def _parse(argv: Sequence[str]) -> argparse.Namespace:
    parser = argparse.ArgumentParser(prog="hlvs bench bringup", description=__doc__)
    parser.add_argument("--robots", type=int, default=8, choices=(2, 4, 6, 8),
                        help="robots in the match, both teams together (default 8)")
    parser.add_argument("--json", action="store_true", help="print only the JSON line")
    parser.add_argument("--timeout", type=float, default=90.0,
                        help="seconds to wait for every robot to connect (default 90)")
    parser.add_argument("--keep", type=user_path, default=None, help="keep the match folder here")
    parser.add_argument("--robot-image", default=None,
                        help="image of every robot (default: the project's stub image)")
    parser.add_argument("--robot-command", default=None,
                        help="dockerCmd of every robot (default: the stub's goalie / striker)")
    parser.add_argument("--holders", action="store_true",
                        help="each robot in the network of a holder container, as where the "
                             "start gate cannot be built (default: behind the start gate)")
    return parser.parse_args(list(argv))


def measure(*, robots: int, out: Path, timeout_s: float, robot_image: str | None = None,
            robot_command: str | None = None, holders: bool = False) -> dict[str, object]:
    from orchestrator import add_scrimmage_arguments as add_arguments
    from orchestrator.config.loader import load_game
    from orchestrator.engine import connect
    from orchestrator.engine.containers import DockerRuntime
    from orchestrator.match import (
        AllConnected,
        HostControl,
        MatchEnded,
        MatchOutcome,
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
    args = scrim.parse_args(["--players", str(robots // 2), "--half-duration", "60",
                             "--wait-before-ready", "60", "--grace", "1",
                             "--match-id", f"bringup-{int(time.time())}"]
                            + (["--robot-command", robot_command] if robot_command else []))
    stub = robot_image or project_image("stub")
    simulator = project_image("simulator")
    request = ScrimmageRequest.from_options(args)
    plan = plan_from_game(load_game(write_files(request, out / "config", stub_image=stub)),
                          grace_period_s=1.0)
    runtime = DockerRuntime(connect())
    gate = None if holders else start_gate()
    runner = MatchRunner(
        plan, runtime=runtime, host=HostControl.for_current_user(),
        options=RunOptions(out_dir=out, simulator_image=simulator, poll_s=0.05,
                           start_gate=gate),
        telemetry=lambda endpoint, match_id: ZenohTelemetry(endpoint=endpoint, match_id=match_id),
    )
    events = runner.events.subscribe()  # bring-up is seen as it happens, not polled
    outcomes: list[MatchOutcome] = []
    thread = threading.Thread(target=lambda: outcomes.append(runner.run()),
                              name="bringup-match", daemon=True)
    thread.start()
    deadline = time.monotonic() + timeout_s
    while (left := deadline - time.monotonic()) > 0:
        try:
            event = events.get(timeout=left)
        except queue.Empty:
            break
        if isinstance(event, AllConnected | MatchEnded):
            break
    runner.stop_event.set()
    thread.join(timeout=120)
    cleanup(runtime, HostControl.for_current_user(), match_id=plan.match_id)
    outcome = outcomes[0] if outcomes else None
    bringup = outcome.bringup_s if outcome is not None else None
    timings = outcome.results.timings_s if outcome is not None and outcome.results else {}
    containers = timings.get("starting")
    startup = outcome.startup if outcome is not None else None
    steps = startup.robot_steps_s.values() if startup is not None else []
    names = sorted({name for robot in steps for name in robot})
    return {
        "bench": "bringup",
        "robots": robots,
        # robots behind the start gate (False: each in the network of a holder container)
        "start_gate": gate is not None,
        "bringup_s": None if bringup is None else round(bringup, 3),
        "containers_s": containers,
        # where the time goes: STARTING's phases in order (networks, firewall, spec, containers:
        # the simulator and the robots started 8 at a time; simulator: its own create + start),
        # the slowest robot's time in each step of its start,
        # and what follows STARTING until every robot is connected (the simulator's boot, the
        # robots' processes starting and connecting)
        "phases_s": dict(startup.phases_s) if startup is not None else {},
        "robot_steps_max_s": {n: max(r.get(n, 0.0) for r in steps) for n in names},
        "after_containers_s": None if bringup is None or containers is None
        else round(bringup - containers, 3),
        "target_s": TARGET_S,
        "ok": bringup is not None and bringup <= TARGET_S,
    }


def main(argv: Sequence[str]) -> int:
    args = _parse(argv)
    try:
        if args.keep is not None:
            result = measure(robots=args.robots, out=args.keep, timeout_s=args.timeout,
                             robot_image=args.robot_image, robot_command=args.robot_command,
                             holders=args.holders)
        else:
            with tempfile.TemporaryDirectory(prefix="hlvs-bringup-") as folder:
                result = measure(robots=args.robots, out=Path(folder), timeout_s=args.timeout,
                                 robot_image=args.robot_image, robot_command=args.robot_command,
                                 holders=args.holders)
    except OrchestratorError as exc:
        print(json.dumps({"bench": "bringup", "error": str(exc)}))
        return exc.exit_code
    print(json.dumps(result))
    return 0 if result["bringup_s"] is not None else 1


__all__ = ["main", "measure"]
