"""``/v1/ladder``: the league table of ratings (:mod:`service.ratings`) and each team's rating
history and rated matches. Any signed-in team or operator may read it."""

from __future__ import annotations

from datetime import datetime
from typing import Annotated, Literal

from fastapi import APIRouter, Depends, FastAPI, Request
from pydantic import BaseModel, Field

from service import tokens
from service.deps import DbSession, SessionRoute, get_services, require_token
from service.errors import NotFound
from service.ratings import FRIENDLY, Ladder, RatedGame, TeamRating

router = APIRouter(prefix="/v1/ladder", tags=["ladder"], route_class=SessionRoute)
AnyPrincipal = Annotated[tokens.Principal, Depends(require_token)]


class LadderRow(BaseModel):
    rank: int = Field(description="1 = the best rating")
    team: str
    rating: float = Field(description="OpenSkill's ordinal, mu - 3 sigma")
    mu: float
    sigma: float
    played: int
    won: int
    drawn: int
    lost: int
    goals_for: int
    goals_against: int


class LadderView(BaseModel):
    teams: list[LadderRow]
    matches_rated: int
    ladder_every_s: float = Field(description="how often the ladder schedules a friendly; 0: off")


class RatingPoint(BaseModel):
    """The team's rating after one of its matches (the first point: before any)."""

    at: datetime | None
    rating: float
    mu: float
    sigma: float


class LadderMatch(BaseModel):
    source: Literal["friendly", "official"]
    id: str = Field(description="the submission id of a friendly, the schedule's match id of "
                                "an official match")
    played_at: datetime
    color: Literal["red", "blue"]
    opponent: str
    goals_for: int
    goals_against: int
    outcome: Literal["won", "drawn", "lost"]
    rating_before: float
    rating_after: float
    replay_url: str | None = Field(description="the replay page of a friendly")


class TeamLadderView(BaseModel):
    team: LadderRow
    history: list[RatingPoint]
    matches: list[LadderMatch] = Field(description="newest first")


def _ladder(request: Request, session: DbSession) -> Ladder:
    return get_services(request).ladder.get(session)


def _row(rank: int, t: TeamRating) -> LadderRow:
    return LadderRow(rank=rank, team=t.team, rating=round(t.rating, 3), mu=round(t.mu, 3),
                     sigma=round(t.sigma, 3), played=t.played, won=t.won, drawn=t.drawn,
                     lost=t.lost, goals_for=t.goals_for, goals_against=t.goals_against)


def _ordinal(mu_sigma: tuple[float, float]) -> float:
    return round(mu_sigma[0] - 3 * mu_sigma[1], 3)


def _match(team: str, game: RatedGame) -> LadderMatch:
    color: Literal["red", "blue"] = "red" if game.red.team == team else "blue"
    me, other = (game.red, game.blue) if color == "red" else (game.blue, game.red)
    outcome: Literal["won", "drawn", "lost"] = (
        "drawn" if game.winner == "draw" else "won" if game.winner == color else "lost")
    return LadderMatch(
        source="friendly" if game.source == FRIENDLY else "official", id=game.ref,
        played_at=game.played_at, color=color, opponent=other.team, goals_for=me.goals,
        goals_against=other.goals, outcome=outcome, rating_before=_ordinal(me.before),
        rating_after=_ordinal(me.after),
        replay_url=f"/watch/replay/{game.ref}" if game.source == FRIENDLY else None)


@router.get("")
def get_ladder(request: Request, principal: AnyPrincipal, session: DbSession) -> LadderView:
    """Every team on the ladder, best rating first."""
    ladder = _ladder(request, session)
    return LadderView(teams=[_row(n, t) for n, t in enumerate(ladder.table(), start=1)],
                      matches_rated=len(ladder.games),
                      ladder_every_s=get_services(request).settings.ladder_every_s)


@router.get("/{team}", responses={404: {"description": "no team of that name on the ladder"}})
def get_team(team: str, request: Request, principal: AnyPrincipal,
             session: DbSession) -> TeamLadderView:
    """A team's rating history (oldest first) and its rated matches (newest first)."""
    ladder = _ladder(request, session)
    table = ladder.table()
    rank = next((n for n, t in enumerate(table, start=1) if t.team == team), None)
    if rank is None:
        raise NotFound(what="team on the ladder", ident=team)
    games = ladder.games_of(team)
    first = games[0].red.before if games and games[0].red.team == team else (
        games[0].blue.before if games else (table[rank - 1].mu, table[rank - 1].sigma))
    history = [RatingPoint(at=None, rating=_ordinal(first), mu=round(first[0], 3),
                           sigma=round(first[1], 3))]
    for game in games:
        side = game.red if game.red.team == team else game.blue
        history.append(RatingPoint(at=game.played_at, rating=_ordinal(side.after),
                                   mu=round(side.after[0], 3), sigma=round(side.after[1], 3)))
    return TeamLadderView(team=_row(rank, table[rank - 1]), history=history,
                          matches=[_match(team, g) for g in reversed(games)])


def mount(app: FastAPI) -> None:
    app.include_router(router)


__all__ = ["mount", "router"]
