"""The scheduler's jobs: importable functions of (state file, match id), as APScheduler stores them.

Each job opens the tournament from its state file, checks the ledger and moves the match with a
compare-and-set, so a job that runs twice, late, or after a restart never repeats a step that
was done. Knockout slots ("winner of X") are resolved when the match is pulled or played.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass, replace
from datetime import UTC, datetime, timedelta
from pathlib import Path

from orchestrator.config.schedule import PlannedMatch, Schedule, Slot, load_schedule
from orchestrator.errors import DeliveryError, OrchestratorError, ScheduleError
from tournament.services import (
    DEFAULT_SERVICES,
    MatchContext,
    TournamentServices,
    load_services,
)
from tournament.state import Ledger, ScheduledMatchState

log = logging.getLogger(__name__)

S = ScheduledMatchState


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
        schedule = load_schedule(schedule_path)
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
        planned = self.planned(match_id)
        red, blue = self.resolve(planned.match.red), self.resolve(planned.match.blue)
        if red is None or blue is None:
            return None
        return MatchContext(
            schedule=self.schedule,
            planned=planned,
            red=self.schedule.team(red),
            blue=self.schedule.team(blue),
            out_dir=self.schedule.output_dir / match_id,
        )


def _now() -> datetime:
    return datetime.now(UTC)


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
    if row.state is not S.PLANNED:
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
    result = outcome.as_dict(ctx)
    if outcome.status in ("success", "team_startup", "team_crash", "image_pull"):
        t.ledger.transition(match_id, (S.PLAYING,), S.PLAYED, result=result, note=outcome.status)
    else:
        t.ledger.transition(
            match_id,
            (S.PLAYING,),
            S.FAILED,
            result=result,
            note=f"{outcome.status}: {outcome.cause}",
        )


def deliver_job(state_path: str, match_id: str) -> None:
    t = Tournament.open(state_path)
    if not t.ledger.transition(match_id, (S.PLAYED,), S.DELIVERING):
        return
    ctx = t.context(match_id)
    assert ctx is not None
    try:
        summary = t.services.deliver(ctx)
    except DeliveryError as exc:
        t.ledger.transition(match_id, (S.DELIVERING,), S.LOGS_PENDING, note=str(exc))
        return
    t.ledger.transition(match_id, (S.DELIVERING,), S.DELIVERED, note=summary)
