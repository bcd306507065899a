"""``/v1/league`` and ``/v1/league/{team}``: the league table (:mod:`service.league`) and one
team's rating history with its matches. Any token (team or operator)."""

from __future__ import annotations

from typing import Annotated, Any

from fastapi import APIRouter, Depends, FastAPI, Request
from pydantic import BaseModel
from sqlalchemy import select

from service import league
from service.db import Team
from service.deps import DbSession, get_services, require_token
from service.errors import NotFound
from service.tokens import Principal

router = APIRouter(prefix="/v1", tags=["league"])
AnyPrincipal = Annotated[Principal, Depends(require_token)]


class LeagueTable(BaseModel):
    table: list[dict[str, Any]]
    rating: str


class TeamHistory(BaseModel):
    team: str
    standing: dict[str, Any]
    history: list[dict[str, Any]]


def _standings(request: Request, session: DbSession) -> list[league.Standing]:
    pool = get_services(request).pool
    if pool is None:
        return []
    return league.league(session, pool.results_dir)


@router.get("/league")
def league_table(request: Request, principal: AnyPrincipal, session: DbSession) -> LeagueTable:
    """Every team by rating: OpenSkill (Plackett-Luce) over the friendlies played between
    teams; ``rating`` is ``mu - 3 sigma``."""
    standings = _standings(request, session)
    return LeagueTable(table=[s.as_dict(rank) for rank, s in enumerate(standings, start=1)],
                       rating="OpenSkill Plackett-Luce; rating = mu - 3 sigma")


@router.get("/league/{team}")
def team_history(team: str, request: Request, principal: AnyPrincipal,
                 session: DbSession) -> TeamHistory:
    """One team's place, its rating after each match and the matches with replay links."""
    standings = _standings(request, session)
    for rank, standing in enumerate(standings, start=1):
        if standing.team == team:
            return TeamHistory(team=team, standing=standing.as_dict(rank),
                               history=[h.as_dict() for h in reversed(standing.history)])
    known = list(session.scalars(select(Team.name).order_by(Team.name)))
    raise NotFound(what="team", ident=f"{team} (teams: {', '.join(known) or 'none'})")


def mount(app: FastAPI) -> None:
    app.include_router(router)
