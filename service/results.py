"""The results of finished test matches, kept in the database.

The queue worker reads a match's ``results.json`` once, as a typed
:class:`contracts.MatchResults`, when it ends the submission, and writes its score, play summary
and each side's figures (:mod:`service.db.results`) in the transaction that ends it
(:func:`record`). Everything after reads the rows as a :class:`MatchSummary`: the API
(``GET /v1/matches``, ``GET /v1/submissions/{id}``), the pages' scores, the ladder and the
notifications, so a match folder removed later takes none of it away. The submitting team plays
red, its opponent (a team, or the stub) blue.

A database made before these tables is filled when the worker starts (:func:`backfill`): every
ended submission without a row whose match folder still holds a ``results.json``.
"""

from __future__ import annotations

import logging
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass
from pathlib import Path

from pydantic import BaseModel, ConfigDict, Field
from sqlalchemy import exists, select
from sqlalchemy.orm import Session

from contracts import ContractError, MatchResults, files
from service.db import Submission, SubmissionState, Team
from service.db.results import MatchResultRow, MatchTeamRow

log = logging.getLogger(__name__)

COLORS = ("red", "blue")
ENDED = (SubmissionState.DONE.value, SubmissionState.FAILED.value,
         SubmissionState.CANCELLED.value)


class SideResult(BaseModel):
    """One side of a finished match: its goals, what the referee counted of its play (null
    when no football was played) and how its robots ended. The same figures are kept in the
    database (:class:`~service.db.results.MatchTeamRow`) and answered by the API."""

    model_config = ConfigDict(frozen=True)

    team: str
    goals: int | None
    kicks: int | None
    shots: int | None
    own_goals: int | None
    falls: int | None
    robots: int
    robots_exited: int = Field(description="robots that exited during the game")
    robots_oom_killed: int


@dataclass(frozen=True, slots=True, kw_only=True)
class MatchSummary:
    """What the service keeps of a match's ``results.json``."""

    match_id: str
    status: str  # success | failed
    failure_class: str | None
    failure_team: str | None  # red | blue, when one side caused the failure
    final_state: str | None
    winner: str | None  # red | blue | draw
    score: dict[str, int] | None
    shootout: dict[str, int] | None
    halves_playing: tuple[int, ...] | None  # None: no play was recorded
    playing_s: float | None
    sim_time_ms: int | None
    real_time_factor: float | None
    sides: dict[str, SideResult]  # by colour: red, blue

    @property
    def kicked_off(self) -> bool:
        """Football was played: a half reached PLAYING and some time passed in it."""
        return bool(self.halves_playing) and (self.playing_s or 0.0) > 0

    @property
    def teams(self) -> dict[str, str]:
        return {color: side.team for color, side in self.sides.items()}

    @classmethod
    def of(cls, results: MatchResults, teams: Mapping[str, str]) -> MatchSummary:
        """The summary of ``results``; ``teams``: the team name of each colour."""
        play = results.play
        score = results.score
        sides = {}
        for color in COLORS:
            robots = [r for key, r in results.robots.items() if key.startswith(f"{color}-")]
            sides[color] = SideResult(
                team=teams.get(color, "?"),
                goals=score.get(color) if score is not None else None,
                kicks=play.kicks.get(color) if play else None,
                shots=play.shots.get(color) if play else None,
                own_goals=play.own_goals.get(color) if play else None,
                falls=play.falls.get(color) if play else None,
                robots=len(robots), robots_exited=sum(r.exited_during_game for r in robots),
                robots_oom_killed=sum(r.oom_killed for r in robots))
        failure = results.failure
        return cls(
            match_id=results.match_id, status=results.status,
            failure_class=failure.failure_class.value if failure else None,
            failure_team=failure.team if failure else None, final_state=results.final_state,
            winner=results.winner, score=dict(score) if score is not None else None,
            shootout=dict(results.shootout) if results.shootout is not None else None,
            halves_playing=tuple(play.halves_playing) if play else None,
            playing_s=play.playing_s if play else None, sim_time_ms=results.sim_time_ms,
            real_time_factor=results.real_time_factor, sides=sides)

    @classmethod
    def from_row(cls, row: MatchResultRow) -> MatchSummary:
        score = None if row.red_goals is None or row.blue_goals is None else {
            "red": row.red_goals, "blue": row.blue_goals}
        shootout = None if row.red_shootout is None or row.blue_shootout is None else {
            "red": row.red_shootout, "blue": row.blue_shootout}
        halves = None if row.halves_playing is None else tuple(
            int(half) for half in row.halves_playing.split(",") if half)
        sides = {t.color: SideResult(
            team=t.team, goals=t.goals, kicks=t.kicks, shots=t.shots,
            own_goals=t.own_goals, falls=t.falls, robots=t.robots,
            robots_exited=t.robots_exited, robots_oom_killed=t.robots_oom_killed)
            for t in row.teams}
        return cls(match_id=row.match_id, status=row.status, failure_class=row.failure_class,
                   failure_team=row.failure_team, final_state=row.final_state,
                   winner=row.winner, score=score, shootout=shootout, halves_playing=halves,
                   playing_s=row.playing_s, sim_time_ms=row.sim_time_ms,
                   real_time_factor=row.real_time_factor, sides=sides)


def read_results(out: Path) -> MatchResults | None:
    """The ``results.json`` of the match folder ``out``, None when there is none or it cannot
    be read (logged)."""
    path = out / files.RESULTS
    if not path.is_file():
        return None
    try:
        return MatchResults.load(path)
    except ContractError as exc:
        log.warning("unreadable %s: %s", path, exc)
        return None


def record(session: Session, submission_id: str, summary: MatchSummary) -> None:
    """Write the result of a submission's match (once: a second call leaves the first)."""
    if session.get(MatchResultRow, submission_id) is not None:
        return
    score, shootout = summary.score or {}, summary.shootout or {}
    row = MatchResultRow(
        submission_id=submission_id, match_id=summary.match_id, status=summary.status,
        failure_class=summary.failure_class, failure_team=summary.failure_team,
        final_state=summary.final_state, winner=summary.winner,
        red_goals=score.get("red"), blue_goals=score.get("blue"),
        red_shootout=shootout.get("red"), blue_shootout=shootout.get("blue"),
        halves_playing=None if summary.halves_playing is None else ",".join(
            str(half) for half in summary.halves_playing),
        playing_s=summary.playing_s, sim_time_ms=summary.sim_time_ms,
        real_time_factor=summary.real_time_factor)
    row.teams = [MatchTeamRow(
        color=color, team=side.team, goals=side.goals, kicks=side.kicks, shots=side.shots,
        own_goals=side.own_goals, falls=side.falls, robots=side.robots,
        robots_exited=side.robots_exited, robots_oom_killed=side.robots_oom_killed)
        for color, side in summary.sides.items()]
    session.add(row)
    session.flush()


def stored(session: Session, submission_id: str) -> MatchSummary | None:
    """The recorded result of a submission's match, None when it has none."""
    row = session.get(MatchResultRow, submission_id)
    return MatchSummary.from_row(row) if row is not None else None


def stored_many(session: Session, submission_ids: Iterable[str]) -> dict[str, MatchSummary]:
    """The recorded results of these submissions, by submission id (those without one left
    out)."""
    ids = list(submission_ids)
    if not ids:
        return {}
    rows = session.scalars(select(MatchResultRow).where(MatchResultRow.submission_id.in_(ids)))
    return {row.submission_id: MatchSummary.from_row(row) for row in rows}


def teams_of(session: Session, row: Submission) -> dict[str, str]:
    """The team of each colour: the submitting team red, its opponent blue."""
    team = session.get(Team, row.team_id)
    return {"red": team.name if team is not None else "?", "blue": row.opponent}


def backfill(session: Session, results_dir: Callable[[str], Path]) -> int:
    """Record the result of every ended submission that has none yet and whose match folder
    (``results_dir(pool_handle)``) still holds a ``results.json``; the number recorded."""
    known = exists().where(MatchResultRow.submission_id == Submission.id)
    rows = list(session.scalars(select(Submission).where(
        Submission.state.in_(ENDED), Submission.pool_handle.is_not(None), ~known)))
    added = 0
    for row in rows:
        assert row.pool_handle is not None
        results = read_results(results_dir(row.pool_handle))
        if results is None:
            continue
        record(session, row.id, MatchSummary.of(results, teams_of(session, row)))
        added += 1
    if added:
        log.info("results of %d ended match(es) recorded from their folders", added)
    return added


__all__ = [
    "MatchSummary",
    "SideResult",
    "backfill",
    "read_results",
    "record",
    "stored",
    "stored_many",
    "teams_of",
]
