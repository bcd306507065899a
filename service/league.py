"""The league table teams climb: OpenSkill ratings from the friendlies teams played against each
other (submitted by a team or scheduled by the ladder, :mod:`service.league_ladder`).

Ratings are not stored: they are replayed from the played matches in the order they finished
(Plackett-Luce model of the ``openskill`` package, one rating per team), so the table, each
team's rating history and its match list always agree with the matches themselves. Only a match
that was played counts (state ``done``: a failed, cancelled or not-played match changes no
rating); matches against the stub are test matches, not league matches. A team's place is its
conservative rating (``mu - 3 sigma``, OpenSkill's ordinal), so a team climbs by playing and
winning, not by one lucky result.
"""

from __future__ import annotations

import json
import logging
from dataclasses import dataclass, field
from datetime import datetime
from pathlib import Path
from typing import Any

from openskill.models import PlackettLuce
from sqlalchemy import select
from sqlalchemy.orm import Session

from contracts import files
from service.db import Submission, SubmissionState, Team, utc

log = logging.getLogger(__name__)

STUB = "stub"


@dataclass(slots=True)
class RatedMatch:
    """One played friendly as the table counts it (``red`` submitted it or was the ladder's
    first pick; ``blue`` the opponent)."""

    submission_id: str
    finished_at: datetime
    red: str
    blue: str
    score: dict[str, int]
    winner: str  # red | blue | draw


@dataclass(slots=True)
class HistoryEntry:
    submission_id: str
    at: datetime
    opponent: str
    score: str  # own : opponent's
    outcome: str  # won | drawn | lost
    rating: float  # ordinal after the match
    mu: float
    sigma: float

    def as_dict(self) -> dict[str, Any]:
        return {"submission": self.submission_id, "at": self.at.isoformat(),
                "opponent": self.opponent, "score": self.score, "outcome": self.outcome,
                "rating": round(self.rating, 3), "mu": round(self.mu, 3),
                "sigma": round(self.sigma, 3),
                "replay": f"/watch/replay/{self.submission_id}"}


@dataclass(slots=True)
class Standing:
    team: str
    mu: float
    sigma: float
    played: int = 0
    won: int = 0
    drawn: int = 0
    lost: int = 0
    history: list[HistoryEntry] = field(default_factory=list)

    @property
    def rating(self) -> float:
        """OpenSkill's ordinal, ``mu - 3 sigma``: the rating the table is ordered by."""
        return self.mu - 3.0 * self.sigma

    def as_dict(self, rank: int) -> dict[str, Any]:
        return {"rank": rank, "team": self.team, "rating": round(self.rating, 3),
                "mu": round(self.mu, 3), "sigma": round(self.sigma, 3),
                "played": self.played, "won": self.won, "drawn": self.drawn,
                "lost": self.lost}


def played_friendlies(session: Session, results_dir: Any) -> list[RatedMatch]:
    """Every done friendly between two teams, oldest first; ``results_dir(handle)`` is the
    pool's folder of a match (its results.json gives the score)."""
    names = {t.id: t.name for t in session.scalars(select(Team))}
    rows = session.scalars(select(Submission).where(
        Submission.state == SubmissionState.DONE.value, Submission.opponent != STUB,
        Submission.pool_handle.is_not(None)).order_by(Submission.finished_at, Submission.seq))
    matches = []
    for row in rows:
        assert row.pool_handle is not None
        results = _results(Path(results_dir(row.pool_handle)) / files.RESULTS)
        score, winner = results.get("score"), results.get("winner")
        if not isinstance(score, dict) or winner not in ("red", "blue", "draw"):
            continue  # not played to a result: not rated
        matches.append(RatedMatch(
            submission_id=row.id, finished_at=utc(row.finished_at or row.created_at),
            red=names.get(row.team_id, f"team {row.team_id}"), blue=row.opponent,
            score={"red": int(score["red"]), "blue": int(score["blue"])}, winner=winner))
    return matches


def _results(path: Path) -> dict[str, Any]:
    try:
        data: dict[str, Any] = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return {}
    return data


def table(matches: list[RatedMatch], teams: list[str]) -> list[Standing]:
    """Ratings replayed over ``matches`` (oldest first); every team in ``teams`` has a row,
    ordered by rating (then name)."""
    model = PlackettLuce()
    ratings = {name: model.rating(name=name) for name in teams}
    standings = {name: Standing(team=name, mu=r.mu, sigma=r.sigma) for name, r in ratings.items()}
    for match in matches:
        for name in (match.red, match.blue):
            if name not in ratings:
                ratings[name] = model.rating(name=name)
                standings[name] = Standing(team=name, mu=ratings[name].mu,
                                           sigma=ratings[name].sigma)
        ranks: list[float] = {"red": [1.0, 2.0], "blue": [2.0, 1.0],
                              "draw": [1.0, 1.0]}[match.winner]
        [[red], [blue]] = model.rate([[ratings[match.red]], [ratings[match.blue]]], ranks=ranks)
        ratings[match.red], ratings[match.blue] = red, blue
        for color, name, other, own_goals, their_goals in (
                ("red", match.red, match.blue, match.score["red"], match.score["blue"]),
                ("blue", match.blue, match.red, match.score["blue"], match.score["red"])):
            entry = standings[name]
            entry.mu, entry.sigma = ratings[name].mu, ratings[name].sigma
            entry.played += 1
            outcome = "drawn" if match.winner == "draw" else \
                "won" if match.winner == color else "lost"
            if outcome == "won":
                entry.won += 1
            elif outcome == "lost":
                entry.lost += 1
            else:
                entry.drawn += 1
            entry.history.append(HistoryEntry(
                submission_id=match.submission_id, at=match.finished_at, opponent=other,
                score=f"{own_goals} : {their_goals}", outcome=outcome, rating=entry.rating,
                mu=entry.mu, sigma=entry.sigma))
    return sorted(standings.values(), key=lambda s: (-s.rating, s.team))


def league(session: Session, results_dir: Any) -> list[Standing]:
    """The league table of this service's teams."""
    teams = [t.name for t in session.scalars(select(Team).order_by(Team.name))]
    return table(played_friendlies(session, results_dir), teams)


__all__ = ["HistoryEntry", "RatedMatch", "Standing", "league", "played_friendlies", "table"]
