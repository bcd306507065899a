"""The ladder's ratings: every played match between two teams, rated with OpenSkill.

Which matches count: friendlies (a test match whose opponent is a team) and, when the
service is given the tournament's state (``HLVS_SERVICE_SCHEDULE_STATE``), the official matches
of the schedule. A match counts only when football was played: its result (recorded by the
queue worker from ``results.json``, :mod:`service.results`) has a half that reached PLAYING
and some time in PLAYING (``play.halves_playing``, ``play.playing_s``). A win, a draw and a
loss are the ranks of the two teams (a draw ties them); the goals only fill the table.

A friendly that got past kick-off is rated whatever happens after it (:func:`friendly_outcome`):
finished, its score; cancelled by the asking team, the asking team forfeits (the opponent wins,
recorded 0:0 as ``hlvs match`` records a forfeit); failed, the team the failure is on forfeits,
and a failure on no team's side (the league's) leaves the score as it stood. Only a friendly
that never reached kick-off is not rated.

Each match is recorded once (:class:`service.db.ladder.RatedMatch`, unique by source and id,
written in the transaction that finds it), so a restart or a second look never counts it twice.
The ratings themselves are not stored: they are the OpenSkill (Plackett-Luce) updates of the
counted matches in the order they were recorded, recomputed when that list changes. A team's
*rating* is OpenSkill's ordinal, ``mu - 3 sigma``: it rises as the team wins and as its rating
becomes certain.
"""

from __future__ import annotations

import threading
from collections.abc import Iterable
from dataclasses import dataclass, field
from datetime import datetime
from pathlib import Path
from typing import TYPE_CHECKING, Any

from openskill.models import PlackettLuce
from sqlalchemy import exists, func, select
from sqlalchemy.orm import Session

from contracts import ContractError, MatchResults, Tally, files
from service.db import Submission, SubmissionState, Team, now, utc
from service.db.ladder import RatedMatch
from service.matchfiles import OWN_COLOR
from service.results import MatchSummary, stored_many
from service.submissions import STUB

if TYPE_CHECKING:
    from tournament import MatchResultRecord

FRIENDLY = "friendly"
OFFICIAL = "official"
OTHER_COLOR = "blue" if OWN_COLOR == "red" else "red"

MODEL = PlackettLuce()
"""OpenSkill's Plackett-Luce model with its defaults (mu 25, sigma 25/3)."""


@dataclass(frozen=True, slots=True)
class Outcome:
    """What a finished match gives the ladder: the goals and the winner, or why it is not rated."""

    red_goals: int | None
    blue_goals: int | None
    winner: str | None  # red | blue | draw
    note: str | None  # None: counted

    @property
    def counted(self) -> bool:
        return self.note is None


def outcome_of(results: MatchSummary | None) -> Outcome:
    """The outcome of a match from its recorded result; a match that did not play, or left no
    result, is not counted (``note`` says why)."""
    if results is None:
        return Outcome(None, None, None, f"no result recorded (no readable {files.RESULTS})")
    score = results.score or {}
    red, blue = score.get("red"), score.get("blue")
    if not results.kicked_off:
        return Outcome(red, blue, None, "the match did not play (no half reached PLAYING)")
    if red is None or blue is None:
        return Outcome(red, blue, None, "the match has no score")
    return Outcome(red, blue, _winner(results.winner, red, blue), None)


def outcome_of_file(results_path: Path) -> Outcome:
    """The outcome of a match from its ``results.json`` (an official match of the tournament,
    whose results the service does not keep)."""
    try:
        results = MatchResults.load(results_path)
    except ContractError as exc:
        return Outcome(None, None, None, f"no readable {files.RESULTS}: {exc}")
    return outcome_of(MatchSummary.of(results, {}))


def _winner(winner: str | None, red: int, blue: int) -> str:
    if winner in ("red", "blue", "draw"):
        return winner
    return "red" if red > blue else "blue" if blue > red else "draw"


def forfeit_by(color: str) -> Outcome:
    """The other colour wins by forfeit, recorded 0:0 (as ``hlvs match`` records a forfeit,
    :class:`contracts.Forfeit`)."""
    return Outcome(0, 0, "blue" if color == "red" else "red", None)


def friendly_outcome(results: MatchSummary | None, state: str, *, cancelled: bool) -> Outcome:
    """A friendly's outcome for the ladder by how it ended (``state`` of its submission;
    ``cancelled``: the asking team asked to stop it). Past kick-off it is always rated."""
    played = outcome_of(results)
    if results is None or state == SubmissionState.DONE.value or not results.kicked_off:
        return played
    if state == SubmissionState.CANCELLED.value or cancelled:
        return forfeit_by(OWN_COLOR)
    if results.failure_team in ("red", "blue"):
        return forfeit_by(results.failure_team)
    if played.red_goals is None or played.blue_goals is None:
        return Outcome(None, None, None, "the match stopped with no score")
    return Outcome(played.red_goals, played.blue_goals,
                   _winner(None, played.red_goals, played.blue_goals), None)


# recording --------------------------------------------------------------------------------
ENDED = (SubmissionState.DONE.value, SubmissionState.CANCELLED.value,
         SubmissionState.FAILED.value)


def record_friendlies(session: Session) -> int:
    """Record every ended friendly not considered yet, from the results the worker recorded
    (:mod:`service.results`); the number recorded."""
    seen = exists().where(RatedMatch.source == FRIENDLY, RatedMatch.ref == Submission.id)
    rows = session.execute(select(Submission, Team.name).join(
        Team, Team.id == Submission.team_id).where(
        Submission.state.in_(ENDED), Submission.opponent != STUB,
        Submission.pool_handle.is_not(None), ~seen).order_by(Submission.finished_at,
                                                             Submission.seq)).all()
    results = stored_many(session, [row.id for row, _ in rows])
    for row, team in rows:
        outcome = friendly_outcome(results.get(row.id), row.state,
                                   cancelled=bool(row.cancel_requested))
        teams = {OWN_COLOR: team, OTHER_COLOR: row.opponent}
        _add(session, source=FRIENDLY, ref=row.id, red=teams["red"], blue=teams["blue"],
             outcome=outcome, played_at=utc(row.finished_at) if row.finished_at else now())
    return len(rows)


def record_official(session: Session, state_file: Path) -> int:
    """Record the tournament's played matches not considered yet (from its ledger)."""
    from tournament import Ledger

    known = set(session.scalars(select(RatedMatch.ref).where(RatedMatch.source == OFFICIAL)))
    added = 0
    for row in Ledger(state_file).rows():
        result = row.result
        if row.id in known or not row.state.played or not result:
            continue
        _add(session, source=OFFICIAL, ref=row.id, red=str(result.get("red_team", row.red)),
             blue=str(result.get("blue_team", row.blue)), outcome=_official_outcome(result),
             played_at=utc(row.updated_at))
        added += 1
    return added


def _official_outcome(result: MatchResultRecord) -> Outcome:
    out_dir = result.get("out_dir")
    if out_dir and (Path(out_dir) / files.RESULTS).is_file():
        return outcome_of_file(Path(out_dir) / files.RESULTS)
    score = result.get("score") or {}
    red, blue = score.get("red"), score.get("blue")
    if not isinstance(red, int) or not isinstance(blue, int):
        return Outcome(None, None, None, "the match has no score")
    return Outcome(red, blue, _winner(result.get("winner"), red, blue), None)


def _add(session: Session, *, source: str, ref: str, red: str, blue: str, outcome: Outcome,
         played_at: datetime) -> None:
    session.add(RatedMatch(source=source, ref=ref, red_team=red, blue_team=blue,
                           red_goals=outcome.red_goals, blue_goals=outcome.blue_goals,
                           winner=outcome.winner, counted=outcome.counted, note=outcome.note,
                           played_at=played_at))
    session.flush()


# the table ----------------------------------------------------------------------------------
@dataclass(slots=True)
class TeamRating(Tally):
    """A team on the ladder: its :class:`contracts.Tally` of rated matches and its OpenSkill
    rating."""

    mu: float = MODEL.mu
    sigma: float = MODEL.sigma

    @property
    def rating(self) -> float:
        """OpenSkill's ordinal: ``mu - 3 sigma``."""
        return self.mu - 3 * self.sigma


@dataclass(frozen=True, slots=True)
class Side:
    team: str
    goals: int
    before: tuple[float, float]  # mu, sigma
    after: tuple[float, float]


@dataclass(frozen=True, slots=True)
class RatedGame:
    id: int
    source: str
    ref: str
    played_at: datetime
    winner: str
    red: Side
    blue: Side


@dataclass(slots=True)
class Ladder:
    """Every team's rating and the rated matches, oldest first."""

    teams: dict[str, TeamRating] = field(default_factory=dict)
    games: list[RatedGame] = field(default_factory=list)

    def table(self) -> list[TeamRating]:
        """Best first: rating, then mu, then name."""
        return sorted(self.teams.values(), key=lambda t: (-t.rating, -t.mu, t.team))

    def games_of(self, team: str) -> list[RatedGame]:
        return [g for g in self.games if team in (g.red.team, g.blue.team)]


def rate(matches: Iterable[RatedMatch], teams: Iterable[str] = ()) -> Ladder:
    """The ladder after ``matches`` (counted ones, in order); ``teams`` appear unrated too."""
    ladder = Ladder(teams={name: TeamRating(team=name) for name in teams})
    for match in matches:
        if not match.counted or match.red_goals is None or match.blue_goals is None:
            continue
        red = ladder.teams.setdefault(match.red_team, TeamRating(team=match.red_team))
        blue = ladder.teams.setdefault(match.blue_team, TeamRating(team=match.blue_team))
        winner = match.winner or _winner(None, match.red_goals, match.blue_goals)
        ranks: list[float] = {"red": [0.0, 1.0], "blue": [1.0, 0.0]}.get(winner, [0.0, 0.0])
        before = {"red": (red.mu, red.sigma), "blue": (blue.mu, blue.sigma)}
        [[new_red], [new_blue]] = MODEL.rate(
            [[MODEL.create_rating([red.mu, red.sigma], name=red.team)],
             [MODEL.create_rating([blue.mu, blue.sigma], name=blue.team)]], ranks=ranks)
        for me, new, goals_for, goals_against, color in (
                (red, new_red, match.red_goals, match.blue_goals, "red"),
                (blue, new_blue, match.blue_goals, match.red_goals, "blue")):
            me.mu, me.sigma = float(new.mu), float(new.sigma)
            # the winner, not the goals: a forfeit is recorded 0:0
            me.count(goals_for, goals_against,
                     "drawn" if winner == "draw" else "won" if winner == color else "lost")
        ladder.games.append(RatedGame(
            id=match.id, source=match.source, ref=match.ref, played_at=utc(match.played_at),
            winner=winner,
            red=Side(match.red_team, match.red_goals, before["red"], (red.mu, red.sigma)),
            blue=Side(match.blue_team, match.blue_goals, before["blue"],
                      (blue.mu, blue.sigma))))
    return ladder


class LadderCache:
    """The ladder, recomputed only when a match was recorded or the teams on it changed since.

    The key holds the names of the teams that accept friendlies (not their count): a team
    renamed, or one team leaving as another joins, changes the table as well."""

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._key: tuple[Any, ...] | None = None
        self._ladder = Ladder()

    def get(self, session: Session) -> Ladder:
        key = (session.scalar(select(func.count(RatedMatch.id))),
               session.scalar(select(func.max(RatedMatch.id))),
               tuple(session.scalars(select(Team.name).where(
                   Team.accepts_friendlies.is_(True)).order_by(Team.name))))
        with self._lock:
            if key == self._key:
                return self._ladder
        matches = session.scalars(select(RatedMatch).where(RatedMatch.counted.is_(True))
                                  .order_by(RatedMatch.id))
        ladder = rate(matches, key[2])
        with self._lock:
            self._key, self._ladder = key, ladder
        return ladder


__all__ = [
    "FRIENDLY",
    "MODEL",
    "OFFICIAL",
    "Ladder",
    "LadderCache",
    "Outcome",
    "RatedGame",
    "TeamRating",
    "outcome_of",
    "outcome_of_file",
    "rate",
    "record_friendlies",
    "record_official",
]
