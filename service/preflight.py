"""The pre-flight check of a submission: a few seconds that spare a failed match hours later.

Stages, in order (the first failure is the answer, with its cause):

1. ``pull``  every image of the team is pulled with the team's registry login;
2. ``size``  each within the league's size limit (10 GB per image);
3. ``start`` one robot per distinct image starts under the official limits (CPUs capped at
   this host's count);
4. ``connect`` and connects to a simulator's robot API within ``preflight_timeout_s``.

Stages 3-4 use the match machinery itself (``MatchRunner``) on a short-lived match of those
robots against one stub robot, stopped as soon as every robot has connected. With
``settings.preflight == "images"`` only stages 1-2 run.
"""

from __future__ import annotations

import contextlib
import logging
import os
import queue
import secrets
import shutil
import tempfile
import threading
import time
from dataclasses import asdict, replace
from pathlib import Path
from typing import Any

from orchestrator import ConfigError, ImageTooLarge, OrchestratorError
from orchestrator.config import Limits, PlayerConfig, TeamConfig
from service.errors import InvalidInput, PreflightFailed
from service.settings import Settings

log = logging.getLogger(__name__)


PREFLIGHT_MATCH_PREFIX = "preflight-"
"""The match id of every pre-flight check starts so."""
PREFLIGHT_FOLDER_PREFIX = "hlvs-preflight-"
PROJECT_PREFIX = "hlvs-runner/"
"""The project's own images (``orchestrator.project_images``): never a team's robot."""


def project_image_name(repository: str | None) -> bool:
    """Whether ``repository`` names one of the project's own images (with or without a
    registry part such as ``docker.io/``)."""
    if not repository:
        return False
    name = repository.lower()
    for prefix in ("docker.io/", "index.docker.io/", "registry-1.docker.io/"):
        name = name.removeprefix(prefix)
    return name.startswith(PROJECT_PREFIX)


def official_limits() -> Limits:
    return replace(Limits(), cpus=min(Limits().cpus, float(os.cpu_count() or 1)))


class PreflightChecker:
    """The service's pre-flight check (a callable); the robots of a passed or failed check are
    stopped and removed in the background, and :meth:`close` waits for that."""

    def __init__(self) -> None:
        self._teardowns: list[threading.Thread] = []
        self._lock = threading.Lock()
        self._engine: Any = None

    def __call__(self, team: TeamConfig, settings: Settings) -> float:
        with self._lock:
            self._teardowns = [t for t in self._teardowns if t.is_alive()]
            if self._engine is None:  # one engine client for every check
                from orchestrator.engine import connect

                try:
                    self._engine = connect()
                except OrchestratorError as exc:
                    raise PreflightFailed(stage="pull", image="(all)", cause=str(exc)) from exc
        return run(team, settings=settings, teardowns=self._teardowns, engine=self._engine)

    def reclaim(self) -> None:
        """:func:`reclaim_leftovers` in a background thread (a check's answer never waits for
        it: the new checks' match ids are new)."""

        def run_reclaim() -> None:
            try:
                reclaim_leftovers()
            except (OrchestratorError, OSError) as exc:
                log.warning("pre-flight leftovers not reclaimed: %s", exc)

        thread = threading.Thread(target=run_reclaim, name="preflight-reclaim", daemon=True)
        thread.start()
        with self._lock:
            self._teardowns.append(thread)

    def close(self) -> None:
        for thread in list(self._teardowns):
            thread.join(timeout=120)


def run(team: TeamConfig, *, settings: Settings,
        teardowns: list[threading.Thread] | None = None, engine: Any = None) -> float:
    """Check the images of ``team`` (as :func:`service.teamfiles.validated_team` gave it);
    returns the seconds it took, raises :class:`PreflightFailed`.

    With ``teardowns``, stopping the check's containers happens in a background thread added
    to that list (the answer does not wait for it); without, before returning."""
    from orchestrator import resolve_team_images
    from orchestrator.engine import connect

    started = time.monotonic()
    for player in team.players:
        if not settings.team_project_images and project_image_name(player.image_repository):
            raise PreflightFailed(stage="pull", image=player.image or "(none)", cause=(
                f"{PROJECT_PREFIX}* images are the league's own (its simulator, stub and "
                "tools), not a team's: push the team's image to its registry and name it "
                "there (HLVS_SERVICE_TEAM_PROJECT_IMAGES=1 allows them for tests)"))
    try:
        engine = engine or connect()
        resolved = resolve_team_images(engine, team, limits=official_limits(),
                                       registry_only=True)
    except OrchestratorError as exc:
        raise PreflightFailed(stage="pull", image="(all)", cause=str(exc)) from exc
    for number in sorted(resolved):
        image = resolved[number]
        if image.error is not None:
            stage = "size" if isinstance(image.error, ImageTooLarge) else "pull"
            raise PreflightFailed(stage=stage, image=image.reference or "(none)",
                                  cause=image.error.reason)
    if settings.preflight == "full":
        with tempfile.TemporaryDirectory(prefix=PREFLIGHT_FOLDER_PREFIX) as folder:
            _start_and_connect(team, Path(folder), settings=settings, teardowns=teardowns)
    elapsed = time.monotonic() - started
    log.info("pre-flight of %s passed in %.1f s", team.name, elapsed)
    return elapsed


def reclaim_leftovers() -> list[str]:
    """Remove what the pre-flight checks of a service process that died (killed, crashed, the
    host's power lost) left behind: their containers, networks and host rules, and their
    temporary folders; run when the service starts. Only checks whose service process is gone
    are touched (a check has a run record naming its process, see
    :mod:`orchestrator.match.ownership`). Returns the checks' match ids."""
    from orchestrator.engine import DockerRuntime, connect
    from orchestrator.match import HostControl, clean_match, ownership

    dead = [r for r in ownership.records()
            if r.match_id.startswith(PREFLIGHT_MATCH_PREFIX) and not ownership.owner_alive(r)]
    if not dead:
        return []
    runtime = DockerRuntime(connect())
    host = HostControl.for_current_user()
    for record in dead:
        report = clean_match(runtime, host, match_id=record.match_id, record=None)
        ownership.forget(record)
        folder = Path(record.out_dir).parent
        if folder.name.startswith(PREFLIGHT_FOLDER_PREFIX):
            shutil.rmtree(folder, ignore_errors=True)
        log.warning("pre-flight %s of a service process that is gone: removed %d containers, "
                    "%d networks%s", record.match_id, len(report.containers),
                    len(report.networks), f" ({'; '.join(report.errors)})" if report.errors
                    else "")
    return [r.match_id for r in dead]


def _invalid(exc: ConfigError) -> InvalidInput:
    """A check that the upload's check did not make, as the upload would answer it."""
    problems = [{**{k: str(v) for k, v in asdict(p).items()}, "file": "team_config.json",
                 "text": str(p)} for p in exc.problems]
    errors = [p for p in problems if p["severity"] == "error"] or problems
    return InvalidInput(f"team_config.json has {len(errors)} problem(s): " + errors[0]["text"],
                        problems=problems)


def _distinct_players(team: TeamConfig) -> TeamConfig:
    """The team with one player per distinct (image, tag, command), numbered from 1."""
    kept: list[PlayerConfig] = []
    seen: set[tuple[str | None, str | None, str | None]] = set()
    for player in team.players:
        ident = (player.image_repository, player.docker_tag, player.docker_cmd)
        if ident not in seen:
            seen.add(ident)
            kept.append(replace(player, number=len(kept) + 1))
    return replace(team, players=tuple(kept))


def _start_and_connect(team: TeamConfig, folder: Path, *, settings: Settings,
                       teardowns: list[threading.Thread] | None) -> None:
    from orchestrator import ZenohTelemetry, project_image
    from orchestrator.config import parse_game, parse_team
    from orchestrator.engine import DockerRuntime, connect
    from orchestrator.match import (
        HostControl,
        MatchRunner,
        RunOptions,
        ScrimmageRequest,
        clean_match,
        game_file,
        ownership,
        plan_from_game,
        start_gate,
        team_file,
    )
    from service.teamfiles import FIELD_CLASS

    checked = _distinct_players(team)
    match_id = PREFLIGHT_MATCH_PREFIX + secrets.token_hex(4)
    request = ScrimmageRequest(players=1, seed=1, half_duration_s=60.0, wait_before_ready_s=120.0,
                               grace_s=1.0)
    game = game_file(request, match_id)
    game["red"]["ports"] = [10000 + n for n in range(1, len(checked.players) + 1)]
    limits = official_limits()
    game["limits"] = {"cpus": limits.cpus, "memory_gb": limits.memory_gb, "pids": limits.pids,
                      "log_folder_gb": 1}
    config = folder / "config"
    try:
        stub = parse_team(team_file("Stub", project_image("stub"), 1, goalie_first=True),
                          source=config / "team_blue.json", field_class=FIELD_CLASS,
                          images_required=True).team
        loaded = parse_game(game, source=config / "game.json", teams={"red": checked, "blue": stub},
                            images_required=True)
        plan = plan_from_game(loaded, grace_period_s=1.0)
    except ConfigError as exc:
        raise _invalid(exc) from None
    runtime = DockerRuntime(connect())
    host = HostControl.for_current_user()
    runner = MatchRunner(
        plan, runtime=runtime, host=host,
        options=RunOptions(out_dir=folder / "out", simulator_image=project_image("simulator"),
                           poll_s=0.1, start_gate=start_gate()),
        telemetry=lambda endpoint, mid: ZenohTelemetry(endpoint=endpoint, match_id=mid),
    )
    events = runner.events.subscribe()
    owned = contextlib.ExitStack()  # a run record: a service killed now leaves what to reclaim
    owned.enter_context(ownership.claim(match_id, folder / "out"))
    thread = threading.Thread(target=runner.run, name=match_id, daemon=True)
    thread.start()
    failure: PreflightFailed | None = None
    try:
        failure = _connected_or_failure(events, timeout_s=settings.preflight_timeout_s,
                                        images=[r.image or "?" for r in plan.red.robots])
    finally:
        runner.stop_event.set()

        def teardown() -> None:
            thread.join(timeout=120)
            with owned:  # the record goes once nothing of the check is left
                clean_match(runtime, host, match_id=match_id, record=None)

        if teardowns is None:
            teardown()
        else:
            background = threading.Thread(target=teardown, name=f"{match_id}-teardown")
            background.start()
            teardowns.append(background)
    if failure is not None:
        raise failure


def _connected_or_failure(events: queue.SimpleQueue[Any], *, timeout_s: float,
                          images: list[str]) -> PreflightFailed | None:
    """Follow the check's match until every robot has connected (None) or the check has
    failed: a robot of the team that did not start or exited, the match itself, or the
    deadline."""
    from orchestrator.match import (
        AllConnected,
        MatchEnded,
        MatchFailed,
        RobotExited,
        RobotNotStarted,
    )

    deadline = time.monotonic() + timeout_s
    while True:
        try:
            event = events.get(timeout=max(0.0, deadline - time.monotonic()))
        except queue.Empty:
            return PreflightFailed(
                stage="connect", image=", ".join(sorted(set(images))),
                cause=f"no connection to the simulator's robot API within {timeout_s:.0f} s")
        if isinstance(event, AllConnected):
            return None
        if isinstance(event, RobotNotStarted) and event.color == "red":
            return PreflightFailed(stage="start", image=event.image or "?", cause=event.cause)
        if isinstance(event, RobotExited) and event.color == "red":
            return PreflightFailed(
                stage="start", image=event.image or "?",
                cause=f"the robot's container exited with code {event.exit_code}"
                      + (" (out of memory)" if event.oom_killed else "")
                      + " before connecting to the simulator")
        if isinstance(event, MatchFailed | MatchEnded):
            cause = event.failure.cause if event.failure else "the check ended early"
            return PreflightFailed(stage="start", image="(simulator)", cause=cause)


__all__ = [
    "PREFLIGHT_MATCH_PREFIX", "PROJECT_PREFIX", "PreflightChecker", "official_limits",
    "project_image_name", "reclaim_leftovers", "run",
]
