"""The scheduler's jobs: importable functions of (state file, match id), as APScheduler stores them.

Each job opens the tournament from its state file, checks the ledger and moves the match with a
compare-and-set, so a job that runs twice, late, or after a restart never repeats a step that
was done. Knockout slots ("winner of X") are resolved when the match is pulled or played.
"""

from __future__ import annotations

import logging
import threading
from dataclasses import dataclass, replace
from datetime import UTC, datetime, timedelta
from pathlib import Path

from orchestrator import OrchestratorError, ScheduleError
from orchestrator.config import PlannedMatch, Schedule, Slot, load_schedule
from tournament.controls import abort_request
from tournament.logs import DONE, TeamLogs, all_done, summary, with_retry
from tournament.services import (
    DEFAULT_SERVICES,
    Abort,
    MatchContext,
    PlayOutcome,
    TournamentServices,
    load_services,
)
from tournament.state import Ledger, ScheduledMatchState

log = logging.getLogger(__name__)

S = ScheduledMatchState
STOPPING = threading.Event()
"""Set when the scheduler process stops: a match that ends then was interrupted, not failed."""
DEFAULT_STOP_GRACE_S = 60.0
"""Seconds a playing match has to stop and collect its logs when the scheduler is stopped
(SIGTERM, Ctrl-C) before it is killed; ``hlvs schedule run --stop-grace``."""


@dataclass(frozen=True, slots=True, kw_only=True)
class Tournament:
    """A schedule, its ledger and its services, opened from the state file."""

    schedule: Schedule
    ledger: Ledger
    services: TournamentServices
    reference: datetime

    @classmethod
    def open(cls, state_path: str | Path) -> Tournament:
        ledger = Ledger(Path(state_path))
        schedule_path = ledger.get_meta("schedule")
        reference = ledger.get_meta("reference")
        if schedule_path is None or reference is None:
            raise ScheduleError(f"{state_path}: not a tournament state file (no schedule recorded)")
        schedule = load_schedule(schedule_path, text=ledger.get_meta("schedule_text"))
        pool = ledger.get_meta("pool")  # hlvs schedule run --pool overrides the file's
        if pool == "slurm":
            schedule = replace(schedule, pool=replace(schedule.pool, kind="slurm"))
        elif pool == "local":
            schedule = replace(schedule, pool=replace(schedule.pool, kind="local"))
        services = load_services(ledger.get_meta("services") or DEFAULT_SERVICES, schedule)
        return cls(
            schedule=schedule,
            ledger=ledger,
            services=services,
            reference=datetime.fromisoformat(reference),
        )

    def planned(self, match_id: str) -> PlannedMatch:
        for planned in self.schedule.plan(self.reference):
            if planned.match.id == match_id:
                return planned
        raise ScheduleError(f"match {match_id!r} is not in {self.schedule.source}")

    def resolve(self, slot: Slot) -> str | None:
        """The team name of a slot, or None while the earlier match has no result."""
        if slot.team is not None:
            return slot.team
        ref = slot.winner_of or slot.loser_of
        assert ref is not None
        result = self.ledger.row(ref).result
        if not result or result.get("winner") not in ("red", "blue"):
            return None
        winner = str(result["winner_team"])
        if slot.winner_of:
            return winner
        return str(result["blue_team"] if winner == result["red_team"] else result["red_team"])

    def context(self, match_id: str) -> MatchContext | None:
        planned = self.planned_now(match_id)
        red, blue = self.resolve(planned.match.red), self.resolve(planned.match.blue)
        if red is None or blue is None:
            return None
        return MatchContext(
            schedule=self.schedule,
            planned=planned,
            red=self.schedule.team(red),
            blue=self.schedule.team(blue),
            out_dir=self.schedule.output_dir / match_id,
            abort=lambda: self.stop_or_abort(match_id),
        )

    def abort_requested(self, match_id: str) -> Abort | None:
        request = abort_request(self.ledger.row(match_id).request)
        return None if request is None else Abort(reason=request[0], grace_s=request[1])

    def stop_or_abort(self, match_id: str) -> Abort | None:
        """What a playing match polls: the scheduler's stop, else the operator's abort."""
        if STOPPING.is_set():
            grace = self.ledger.get_meta("stop_grace_s")
            return Abort(reason="the scheduler is stopping", stop=True,
                         grace_s=float(grace) if grace else DEFAULT_STOP_GRACE_S)
        return self.abort_requested(match_id)

    def planned_now(self, match_id: str) -> PlannedMatch:
        """The match as the ledger has it now (its times may have been rescheduled)."""
        planned = self.planned(match_id)
        row = self.ledger.row(match_id)
        return replace(planned, pull_at=row.pull_at, play_at=row.play_at,
                       stream_start=row.stream_start, stream_end=row.stream_end,
                       deliver_at=row.deliver_at)


def _now() -> datetime:
    return datetime.now(UTC)


def _early(at: datetime) -> bool:
    """A job of a match rescheduled later fired at the old time: its step is not due yet
    (the runner adds the job at the new time)."""
    return _now() < at - timedelta(seconds=1)


def _pull(t: Tournament, match_id: str) -> bool:
    """Pull step; False only when the teams of the match are not known yet (then deferred)."""
    row = t.ledger.row(match_id)
    if row.state is not S.PLANNED:
        return True
    ctx = t.context(match_id)
    if ctx is None:
        if _now() >= row.stream_start:
            t.ledger.transition(
                match_id, (S.PLANNED,), S.MISSED, note="the teams were not known before the stream"
            )
        else:
            until = min(_now() + timedelta(seconds=t.schedule.timing.retry_s), row.stream_start)
            t.ledger.defer(match_id, until, f"waiting for the teams ({row.red} v {row.blue})")
            log.info("match %s: teams not known yet (%s v %s)", match_id, row.red, row.blue)
        return False
    teams = (ctx.red.name, ctx.blue.name)
    if not t.ledger.transition(match_id, (S.PLANNED,), S.PULLING, teams=teams):
        return True  # another run of this step has it
    try:
        summary = t.services.pull(ctx)
        note = f"pulled: {summary}"
    except OrchestratorError as exc:
        # The match is still played: robots without a valid image spawn without a controller,
        # a team with none forfeits; the match runner decides and records it.
        note = f"pull failed: {exc}"
        log.warning("match %s: %s", match_id, note)
    t.ledger.transition(match_id, (S.PULLING,), S.PULLED, note=note)
    log.info("match %s: %s", match_id, note)
    return True


def pull_job(state_path: str, match_id: str) -> None:
    t = Tournament.open(state_path)
    row = t.ledger.row(match_id)
    if row.state is not S.PLANNED or _early(row.pull_at):
        return
    if _now() >= row.stream_start:
        t.ledger.transition(
            match_id, (S.PLANNED,), S.MISSED, note=f"pull window ended at {row.stream_start}"
        )
        return
    _pull(t, match_id)


def play_job(state_path: str, match_id: str) -> None:
    t = Tournament.open(state_path)
    row = t.ledger.row(match_id)
    if _early(row.play_at):
        return
    if row.state is S.PLANNED and not _pull(t, match_id):
        return
    row = t.ledger.row(match_id)
    if row.state is not S.PULLED:
        return
    if _now() >= row.stream_start:
        t.ledger.transition(
            match_id, (S.PULLED,), S.MISSED, note=f"play window closed at {row.stream_start}"
        )
        return
    ctx = t.context(match_id)
    assert ctx is not None
    if not t.ledger.transition(match_id, (S.PULLED,), S.PLAYING, count_attempt=True):
        return
    log.info("match %s: playing %s v %s", match_id, ctx.red.name, ctx.blue.name)
    try:
        outcome = t.services.play(ctx)
    except OrchestratorError as exc:
        t.ledger.transition(match_id, (S.PLAYING,), S.FAILED, note=f"match failed: {exc}")
        return
    aborted = t.abort_requested(match_id)
    if aborted is not None:
        t.ledger.transition(match_id, (S.PLAYING,), S.ABORTED, result=outcome.as_dict(ctx),
                            note=f"aborted by the operator: {aborted.reason}")
        t.ledger.set_request(match_id, None)
        log.warning("match %s: aborted by the operator: %s", match_id, aborted.reason)
        return
    if _needs_shootout(ctx, outcome) and not STOPPING.is_set():
        outcome = _shootout(t, ctx, outcome)
    if STOPPING.is_set() and (outcome.status not in PLAYED_STATUSES
                              or _needs_shootout(ctx, outcome)):
        # the scheduler is stopping (Ctrl-C, SIGTERM): the match (or its shoot-out) was
        # stopped with it; it stays PLAYING (marked interrupted), and the next start replays it
        # into a new attempt folder
        log.warning("match %s: interrupted by the scheduler's stop (%s)", match_id, outcome.cause)
        t.ledger.transition(match_id, (S.PLAYING,), S.PLAYING,
                            note=f"interrupted by the scheduler's stop ({outcome.status}: "
                            f"{outcome.cause or 'not decided'}); played again at the next start")
        return
    result = outcome.as_dict(ctx)
    if outcome.status in PLAYED_STATUSES:
        t.ledger.transition(match_id, (S.PLAYING,), S.PLAYED, result=result, note=outcome.status)
    else:
        t.ledger.transition(
            match_id,
            (S.PLAYING,),
            S.FAILED,
            result=result,
            note=f"{outcome.status}: {outcome.cause}",
        )


PLAYED_STATUSES = ("success", "team_startup", "team_crash", "image_pull")


def _needs_shootout(ctx: MatchContext, outcome: PlayOutcome) -> bool:
    """A knockout match that ended without a winner (e.g. both teams forfeited the same way):
    the league decides it by a penalty shoot-out, as the GameController's KNOCKOUT games do."""
    return (ctx.planned.match.kind == "knockout" and outcome.status in PLAYED_STATUSES
            and outcome.winner not in ("red", "blue"))


def _shootout(t: Tournament, ctx: MatchContext, match: PlayOutcome) -> PlayOutcome:
    """Play a penalty shoot-out (game type PENALTY); its winner wins the match."""
    log.info("match %s: a draw in a knockout match; penalty shoot-out", ctx.match_id)
    try:
        kicks = t.services.shootout(ctx)
    except OrchestratorError as exc:
        return replace(match, status="infrastructure", cause=f"penalty shoot-out failed: {exc}")
    if kicks.status != "success" or kicks.winner not in ("red", "blue"):
        return replace(match, status=kicks.status if kicks.status != "success"
                       else "infrastructure",
                       cause=f"the penalty shoot-out was not decided: {kicks.cause}")
    goals = kicks.shootout or {"red": kicks.score_red or 0, "blue": kicks.score_blue or 0}
    return replace(match, winner=kicks.winner, shootout=goals)


def deliver_job(state_path: str, match_id: str) -> None:
    t = Tournament.open(state_path)
    row = t.ledger.row(match_id)
    retry = row.state is S.LOGS_PENDING
    if not t.ledger.transition(match_id, (S.PLAYED, S.LOGS_PENDING), S.DELIVERING,
                               note="retrying the log delivery" if retry else "delivering logs"):
        return
    ctx = t.context(match_id)
    assert ctx is not None
    previous = {entry.team: entry for entry in row.logs}
    if not retry:
        t.ledger.set_logs(match_id, [TeamLogs(team=name, state="pending")
                                     for name in (ctx.red.name, ctx.blue.name)])
    try:
        found = t.services.redeliver(ctx) if retry else t.services.deliver(ctx)
    except OrchestratorError as exc:  # the store itself failed: nothing was delivered
        found = [TeamLogs(team=name, state="failed", cause=f"store: {exc}")
                 for name in (ctx.red.name, ctx.blue.name)]
    logs = _merge(previous, found, retry=retry,
                  by_hand=_receipts(t.schedule.log_store, ctx.league_id) if retry else {})
    attempts = max((e.attempts for e in logs if e.state == "failed"), default=0)
    if all_done(logs):
        t.ledger.set_logs(match_id, logs)
        t.ledger.transition(match_id, (S.DELIVERING,), S.DELIVERED, note=summary(logs))
        return
    again = 0 < attempts < t.schedule.timing.delivery_attempts
    logs = with_retry(logs, retry=again)
    t.ledger.set_logs(match_id, logs)
    if again:
        t.ledger.transition(match_id, (S.DELIVERING,), S.LOGS_PENDING, note=summary(logs))
        t.ledger.defer(match_id, _now() + timedelta(seconds=t.schedule.timing.retry_s),
                       summary(logs))
    else:
        t.ledger.transition(match_id, (S.DELIVERING,), S.LOGS_FAILED, note=summary(logs))
    log.warning("match %s: %s", match_id, summary(logs))


def _merge(previous: dict[str, TeamLogs], found: list[TeamLogs], *, retry: bool,
           by_hand: dict[str, str] | None = None) -> list[TeamLogs]:
    """This attempt's states over the earlier ones; a retried set that left the store was
    delivered (``by_hand``: team -> target of its receipt) or else is gone (pruned)."""
    merged = dict(previous) if retry else {}
    tried = {entry.team for entry in found}
    for entry in found:
        before = previous.get(entry.team)
        attempts = (before.attempts if before is not None and retry else 0)
        if entry.state in ("delivered", "failed"):
            attempts += 1
        merged[entry.team] = replace(entry, attempts=attempts)
    if retry:
        for team, entry in previous.items():
            if team not in tried and entry.state not in (*DONE, "gone"):
                merged[team] = _left_the_store(entry, (by_hand or {}).get(team))
    return list(merged.values())


def _left_the_store(entry: TeamLogs, receipt_target: str | None) -> TeamLogs:
    if receipt_target is not None:
        return replace(entry, state="delivered", target=receipt_target,
                       cause="delivered by 'hlvs logs deliver'")
    return replace(entry, state="gone",
                   cause="no longer in the log store and never delivered (pruned)")


def _receipts(store: Path, match_id: str | None = None) -> dict[str, str]:
    """team -> target of the delivered sets of ``match_id`` (their receipts in the store)."""
    from orchestrator.delivery import delivered_receipts

    return {r.team: r.target for r in delivered_receipts(store, match_id)}


def settle_hand_deliveries(ledger: Ledger, schedule: Schedule) -> list[str]:
    """LOGS_FAILED matches whose failed sets were delivered since (``hlvs logs deliver`` after
    a fix): their sets become delivered, and the match DELIVERED once every set is; a set that
    left the store without a receipt is gone (pruned). Returns the matches now DELIVERED."""
    from orchestrator.delivery import pending_status

    rows = [r for r in ledger.rows() if r.state is S.LOGS_FAILED]
    if not rows:
        return []
    store = schedule.log_store
    waiting = {(s.match_id, s.team) for s in pending_status(store)}
    settled = []
    for row in rows:
        league_id = schedule.league_match_id(row.id)
        by_hand = _receipts(store, league_id)
        logs = [e if e.state in (*DONE, "gone") or (league_id, e.team) in waiting
                else _left_the_store(e, by_hand.get(e.team)) for e in row.logs]
        if logs == list(row.logs):
            continue
        ledger.set_logs(row.id, logs)
        if all_done(logs):
            if ledger.transition(row.id, (S.LOGS_FAILED,), S.DELIVERED, note=summary(logs)):
                log.info("match %s: %s", row.id, summary(logs))
                settled.append(row.id)
        else:  # the note says what the logs say
            ledger.transition(row.id, (S.LOGS_FAILED,), S.LOGS_FAILED, note=summary(logs))
    return settled
