"""What a tournament does with a match: pull its images, play it, deliver its logs.

:class:`TournamentServices` is the boundary the scheduler's jobs call; :class:`MatchServices`
is the real implementation (images through :mod:`orchestrator.pull`, the match through
``hlvs match`` in a child process that dies with the scheduler, or, with the schedule's pool
``slurm``, as a Slurm job that outlives the scheduler and is adopted by the next one, logs
through :mod:`orchestrator.delivery`). Tests may plug in their own through a
``module:function`` factory.
"""

from __future__ import annotations

import importlib
import json
import logging
import os
import subprocess
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Protocol

from cluster import start_match
from contracts import ContractError, MatchReport, MatchResults, files
from orchestrator import ScheduleError
from orchestrator.config import (
    PlannedMatch,
    Schedule,
    ScheduledTeam,
    SchedulePool,
    game_document,
)
from tournament.logs import TeamLogs
from tournament.state import MatchResultRecord

log = logging.getLogger(__name__)

DEFAULT_SERVICES = "tournament.services:MatchServices"
SLURM_CONF = "/var/lib/hlvs/slurm/slurm.conf"  # written by 'hlvs pool up'
SLURM_POLL_S = 2.0
ABORT_POLL_S = 1.0


@dataclass(frozen=True, slots=True, kw_only=True)
class Abort:
    """An operator's request to stop a running match (``hlvs schedule abort``)."""

    reason: str
    grace_s: float  # after SIGTERM (the match stops and collects its logs), then SIGKILL
    stop: bool = False  # the scheduler itself stops (SIGTERM): the match is played again later


@dataclass(frozen=True, slots=True, kw_only=True)
class MatchContext:
    schedule: Schedule
    planned: PlannedMatch
    red: ScheduledTeam
    blue: ScheduledTeam
    out_dir: Path
    abort: Callable[[], Abort | None] = field(default=lambda: None, compare=False)
    """Polled while the match plays: the operator's abort request, if any."""

    @property
    def match_id(self) -> str:
        return self.planned.match.id

    @property
    def league_id(self) -> str:
        """The match's id outside the tournament (game.json, log sets, the teams' folders)."""
        return self.schedule.league_match_id(self.match_id)

    @property
    def game_path(self) -> Path:
        return self.out_dir / "game.json"


@dataclass(frozen=True, slots=True, kw_only=True)
class PlayOutcome:
    """What the scheduler keeps of a played match (stored as the ledger's result)."""

    status: str  # "success" or the failure class of report.json
    score_red: int | None
    score_blue: int | None
    winner: str | None  # "red" | "blue" | "draw" | None
    cause: str = ""
    shootout: dict[str, int] | None = None  # color -> goals in the penalty shoot-out

    def as_dict(self, ctx: MatchContext) -> MatchResultRecord:
        team = {"red": ctx.red.name, "blue": ctx.blue.name}
        return {
            "status": self.status,
            "score": {"red": self.score_red, "blue": self.score_blue},
            "winner": self.winner,
            "red_team": ctx.red.name,
            "blue_team": ctx.blue.name,
            "winner_team": team.get(self.winner or ""),
            "cause": self.cause,
            "out_dir": str(ctx.out_dir),
            "shootout": self.shootout,
        }


class TournamentServices(Protocol):
    def pull(self, ctx: MatchContext) -> str:
        """Pull the match's images; returns a one-line summary. Raises OrchestratorError."""

    def play(self, ctx: MatchContext) -> PlayOutcome:
        """Play the match into ``ctx.out_dir``."""

    def shootout(self, ctx: MatchContext) -> PlayOutcome:
        """A penalty shoot-out only (game type PENALTY): decides a drawn knockout match."""

    def deliver(self, ctx: MatchContext) -> list[TeamLogs]:
        """Queue the match's logs and deliver them: the state of each team's set."""

    def redeliver(self, ctx: MatchContext) -> list[TeamLogs]:
        """Try again the match's sets that are still in the log store."""


def load_services(ref: str, schedule: Schedule) -> TournamentServices:
    """Build the services from a ``module:callable`` reference (called with the schedule)."""
    module_name, _, attr = ref.partition(":")
    try:
        factory = getattr(importlib.import_module(module_name), attr)
    except (ImportError, AttributeError) as exc:
        raise ScheduleError(f"services {ref!r} cannot be loaded: {exc}") from exc
    services: TournamentServices = factory(schedule)
    return services


def write_game_file(ctx: MatchContext, *, game_type: str | None = None) -> Path:
    """The match's game.json (see :func:`orchestrator.config.schedule.game_document`);
    ``game_type`` PENALTY writes ``game-penalty.json``, a shoot-out only."""
    game = game_document(ctx.schedule, ctx.planned.match, ctx.red, ctx.blue, game_type=game_type)
    ctx.out_dir.mkdir(parents=True, exist_ok=True)
    path = ctx.game_path if game_type is None else ctx.out_dir / f"game-{game_type.lower()}.json"
    path.write_text(json.dumps(game, indent=2) + "\n", encoding="utf-8")
    return path


def keep_earlier_attempt(out: Path) -> Path | None:
    """Move what an earlier attempt left in ``out`` to ``out/attempt-<n>/`` (n = 1, 2, ...,
    as the Slurm pool names a requeued job's attempts), so that playing the match again
    overwrites nothing; returns that folder (None when ``out`` held nothing)."""
    if not out.is_dir():
        return None
    earlier = [p for p in out.iterdir() if not p.name.startswith("attempt-")]
    if not earlier:
        return None
    numbers = [int(p.name.removeprefix("attempt-")) for p in out.glob("attempt-*")
               if p.name.removeprefix("attempt-").isdigit()]
    folder = out / f"attempt-{max(numbers, default=0) + 1}"
    folder.mkdir()
    for path in earlier:
        path.rename(folder / path.name)
    log.info("kept the earlier attempt's files in %s", folder)
    return folder


def _wait_or_abort(ctx: MatchContext, proc: subprocess.Popen[bytes]) -> None:
    """Wait for ``hlvs match``; on an abort request, or when the scheduler stops, SIGTERM it
    (it stops the match and collects what was played), and SIGKILL it when the grace period
    has passed."""
    while proc.poll() is None:
        abort = ctx.abort()
        if abort is None:
            try:
                proc.wait(timeout=ABORT_POLL_S)
            except subprocess.TimeoutExpired:
                pass
            continue
        log.warning("match %s: %s (%s); %g s of grace", ctx.match_id,
                    "stopping" if abort.stop else "aborting", abort.reason, abort.grace_s)
        proc.terminate()
        try:
            proc.wait(timeout=abort.grace_s)
        except subprocess.TimeoutExpired:
            log.warning("match %s: still running after the grace period: killed", ctx.match_id)
            proc.kill()
            proc.wait()


def read_outcome(out_dir: Path) -> PlayOutcome:
    """The outcome of a finished ``hlvs match`` from its report.json and results.json: the
    match's goals, and those of its penalty shoot-out apart (``0-0 (shoot-out 3-2)``)."""
    report_path, results_path = out_dir / files.REPORT, out_dir / files.RESULTS
    if not report_path.is_file():
        return PlayOutcome(
            status="infrastructure",
            score_red=None,
            score_blue=None,
            winner=None,
            cause=f"{report_path} was not written",
        )
    try:
        report = MatchReport.load(report_path)
        results = MatchResults.load(results_path) if results_path.is_file() else None
    except ContractError as exc:
        return PlayOutcome(status="infrastructure", score_red=None, score_blue=None,
                           winner=None, cause=str(exc))
    score_red = results.team_score("red") if results is not None else None
    score_blue = results.team_score("blue") if results is not None else None
    shootout = results.shootout if results is not None else None
    if shootout is None:  # a results.json without the shoot-out kept apart: its score has them
        shootout = shootout_goals(out_dir / "public" / files.SIM_RESULT)
        if shootout is not None and score_red is not None and score_blue is not None:
            score_red -= shootout.get("red", 0)
            score_blue -= shootout.get("blue", 0)
    return PlayOutcome(
        status=report.status,
        score_red=score_red,
        score_blue=score_blue,
        winner=results.winner if results is not None else None,
        cause=report.cause or "",
        shootout=shootout,
    )


def shootout_goals(sim_result: Path) -> dict[str, int] | None:
    """Goals of the penalty shoot-out the referee played (None when there was none)."""
    try:
        data = json.loads(sim_result.read_text(encoding="utf-8"))
        shootout = data.get("shootout")
        if not isinstance(shootout, dict):
            return None
        return {color: int(shootout[color]["scored"]) for color in ("red", "blue")}
    except (OSError, ValueError, KeyError, TypeError, AttributeError):
        return None


class MatchServices:
    """The real thing: registry pulls, a match in Docker, log delivery to the teams' targets."""

    def __init__(self, schedule: Schedule) -> None:
        self.schedule = schedule

    def pull(self, ctx: MatchContext) -> str:
        from orchestrator import pull_game_images

        game = write_game_file(ctx)
        return str(pull_game_images(game))

    def play(self, ctx: MatchContext) -> PlayOutcome:
        return self._play(ctx, write_game_file(ctx), ctx.out_dir / "match")

    def shootout(self, ctx: MatchContext) -> PlayOutcome:
        return self._play(ctx, write_game_file(ctx, game_type="PENALTY"),
                          ctx.out_dir / "shootout")

    def _play(self, ctx: MatchContext, game: Path, out: Path) -> PlayOutcome:
        if self.schedule.pool.kind == "slurm":
            return self._play_in_slurm(ctx, game, out)
        keep_earlier_attempt(out)
        with open(ctx.out_dir / "match.log", "ab") as sink:
            proc = start_match(game, out, sink, die_with_parent=True)
            log.info("match %s: hlvs match %s --out %s (pid %d)", ctx.match_id, game, out,
                     proc.pid)
            _wait_or_abort(ctx, proc)
        outcome = read_outcome(out)
        log.info(
            "match %s: exit %d, %s %s-%s",
            ctx.match_id,
            proc.returncode,
            outcome.status,
            outcome.score_red,
            outcome.score_blue,
        )
        return outcome

    def _play_in_slurm(self, ctx: MatchContext, game: Path, out: Path) -> PlayOutcome:
        """The match as a Slurm job (no requeue: tournament matches wait for the operator).
        A job an earlier scheduler submitted for this match, still in Slurm or finished with
        its report, is adopted instead of playing the match again."""
        from cluster import HOST_NETNS, JobState, MatchJob, PoolError, SlurmPool

        settings = self.schedule.pool
        pool = SlurmPool(
            slurm_conf=settings.slurm_conf or os.environ.get("SLURM_CONF") or SLURM_CONF,
            host_network=Path(HOST_NETNS).exists(), out_subdir="",
        )
        try:
            handle = pool.recorded(out)
            if handle is not None and (pool.active(handle)
                                       or (out / files.REPORT).is_file()):
                log.info("match %s: adopting Slurm job %s", ctx.match_id, pool.job_id(handle))
            else:
                keep_earlier_attempt(out)
                handle = pool.submit(MatchJob(match_id=ctx.league_id, game_path=game,
                                              work_dir=out, account=settings.account,
                                              robot_nodes=_robot_nodes(settings, game)))
                log.info("match %s: Slurm job %s", ctx.match_id, pool.job_id(handle))
            shown = ""
            cancelled = False
            while True:
                status = pool.status(handle)
                if status.state in (JobState.FINISHED, JobState.LOST):
                    break
                abort = ctx.abort()
                if abort is not None and abort.stop:  # the job runs on; the next start adopts it
                    log.warning("match %s: the scheduler stops; Slurm job %s runs on",
                                ctx.match_id, pool.job_id(handle))
                    return PlayOutcome(status="interrupted", score_red=None, score_blue=None,
                                       winner=None, cause=f"{abort.reason}; Slurm job "
                                       f"{pool.job_id(handle)} runs on")
                if abort is not None and not cancelled:
                    log.warning("match %s: aborting Slurm job %s (%s)", ctx.match_id,
                                pool.job_id(handle), abort.reason)
                    pool.cancel(handle)  # SIGTERM, then Slurm's KillWait, then SIGKILL
                    cancelled = True
                if status.detail != shown:
                    log.info("match %s: %s %s", ctx.match_id, status.state.value, status.detail)
                    shown = status.detail
                time.sleep(SLURM_POLL_S)
        except PoolError as exc:
            raise ScheduleError(f"match {ctx.match_id}: Slurm pool: {exc}") from exc
        if status.state is JobState.LOST:
            return PlayOutcome(status="infrastructure", score_red=None, score_blue=None,
                               winner=None, cause=status.detail)
        outcome = read_outcome(out)
        log.info("match %s: %s %s-%s", ctx.match_id, outcome.status, outcome.score_red,
                 outcome.score_blue)
        return outcome

    def deliver(self, ctx: MatchContext) -> list[TeamLogs]:
        from orchestrator.delivery import PUBLIC_TEAM, enqueue_match_logs, pending_status

        store = self.schedule.log_store
        # sets queued by a delivery that a restart interrupted (their files left the match)
        earlier = {s.team for s in pending_status(store) if s.match_id == ctx.league_id}
        teams = {
            "red": (ctx.red.name, ctx.red.credentials),
            "blue": (ctx.blue.name, ctx.blue.credentials),
        }
        created = enqueue_match_logs(
            ctx.out_dir / "match",
            match_id=ctx.league_id,
            teams=teams,
            public_target=self.schedule.public_logs,
            store=store,
        )
        queued = {s.team for s in created} | earlier
        names = [ctx.red.name, ctx.blue.name]
        if self.schedule.public_logs is not None:
            names.append(PUBLIC_TEAM)
        delivered = {e.team: e for e in self.redeliver(ctx) if e.team in queued}
        return [
            delivered.get(name, TeamLogs(team=name, state="pending"))
            if name in queued else TeamLogs(team=name, state="none", cause="no log files")
            for name in names
        ]

    def redeliver(self, ctx: MatchContext) -> list[TeamLogs]:
        """Try the match's sets still in the store (this match's only, never older ones)."""
        from orchestrator.delivery import deliver_pending, pending_status

        store = self.schedule.log_store
        waiting = {s.team for s in pending_status(store) if s.match_id == ctx.league_id}
        outcomes = {o.team: o for o in deliver_pending(store, match_id=ctx.league_id)}
        found = []
        for team in sorted(waiting):
            outcome = outcomes.get(team)
            if outcome is None:  # another process holds the set right now
                found.append(TeamLogs(team=team, state="pending", cause="being delivered"))
            elif outcome.delivered:
                found.append(TeamLogs(team=team, state="delivered", target=outcome.target))
            else:
                error = outcome.error
                cause = f"{error.kind}: {error.reason}" if error is not None else "failed"
                found.append(TeamLogs(team=team, state="failed", cause=cause,
                                      target=outcome.target))
        return found


def _robot_nodes(pool: SchedulePool, game: Path) -> int:
    """League placement: a node for each robot of the match (0: dense placement)."""
    if pool.placement != "league":
        return 0
    from orchestrator.match import robots_in_game

    return robots_in_game(game)
