"""The viewer inside ``hlvs serve``: replays and live views of a team's own test matches.

Mounted by ``hlvs.app``. Replay and live ids are submission ids; every route
needs a token (``Authorization: Bearer``; the pages ask for it once and keep it for the browser
session). A team sees its own matches and the friendlies it played as the opponent; another
team's submission answers 404 like an unknown one. An operator sees every match. The pages for
the queue, the matches, the ladder (routed by :mod:`viewer.ladder_page`), the tournament and
the pool are the same front end, reading the service's own ``/v1`` API with that token;
``/api/viewer/results`` gives those pages the score of every finished match the token may
watch, from the service's database.
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path
from typing import Annotated, Any

from fastapi import APIRouter, Depends, FastAPI, Request
from sqlalchemy import select, true

from contracts import files
from service import DbSession, NotFound, Principal, get_services, require_token, stored_many
from service.db import Scope, Submission, Team
from viewer.api import API_PREFIX, mount_viewer
from viewer.sources import LiveSource, ReplaySource, Teams, live_of

REPLAY = Path("public") / files.REPLAY
STATS = Path("public") / files.API_STATS
LISTING_LIMIT = 200


def _match_dir(request: Request, row: Submission) -> Path | None:
    pool = get_services(request).pool
    if row.pool_handle is None or pool is None:
        return None
    out: Path = pool.results_dir(row.pool_handle)
    return out


def _teams(session: DbSession, row: Submission) -> Teams:
    """The submitting team plays red, its opponent (a team, or the stub) blue."""
    team = session.get(Team, row.team_id)
    return Teams(red=team.name if team is not None else "?", blue=row.opponent)


def _replay_of(row: Submission, out: Path | None, teams: Teams | None = None
               ) -> ReplaySource | None:
    if out is None or not (out / REPLAY).is_file():
        return None
    stats = out / STATS
    return ReplaySource(id=row.id, path=out / REPLAY, stats_path=stats if stats.is_file() else None,
                        teams=teams)


AnyPrincipal = Annotated[Principal, Depends(require_token)]


def _visible(principal: Principal) -> Any:
    """The submissions ``principal`` may watch: all for an operator; a team's own and the
    friendlies it played as the opponent."""
    if principal.scope is Scope.OPERATOR:
        return true()
    return (Submission.team_id == principal.team_id) | (Submission.opponent == principal.team_name)


def _get(session: DbSession, principal: Principal, submission_id: str) -> Submission:
    row = session.scalar(select(Submission).where(Submission.id == submission_id,
                                                  _visible(principal)))
    if row is None:
        raise NotFound(what="submission", ident=submission_id)
    return row


class SubmissionResolver:
    def replay(self, replay_id: str, request: Request, principal: AnyPrincipal,
               session: DbSession) -> ReplaySource:
        row = _get(session, principal, replay_id)
        source = _replay_of(row, _match_dir(request, row), _teams(session, row))
        if source is None:
            raise NotFound(what="replay of submission", ident=f"{row.id} ({row.state})")
        return source

    def live(self, match_id: str, request: Request, principal: AnyPrincipal,
             session: DbSession) -> LiveSource:
        row = _get(session, principal, match_id)
        out = _match_dir(request, row)
        live = live_of(out, id=row.id) if out is not None and row.state == "running" else None
        if live is None:
            raise NotFound(what="running match of submission", ident=f"{row.id} ({row.state})")
        return replace(live, teams=_teams(session, row))

    def listing(self, request: Request, principal: AnyPrincipal, session: DbSession
                ) -> tuple[list[ReplaySource], list[LiveSource]]:
        rows = session.scalars(select(Submission).where(_visible(principal))
                               .order_by(Submission.seq.desc()).limit(LISTING_LIMIT))
        replays, live = [], []
        for row in rows:
            out = _match_dir(request, row)
            source = _replay_of(row, out, _teams(session, row))
            if source is not None:
                replays.append(source)
            elif out is not None and row.state == "running":
                running = live_of(out, id=row.id)
                if running is not None:
                    live.append(replace(running, teams=_teams(session, row)))
        return replays, live


results_router = APIRouter()


@results_router.get(f"{API_PREFIX}/results", include_in_schema=False)
def match_results(request: Request, principal: AnyPrincipal,
                  session: DbSession) -> dict[str, dict[str, Any]]:
    """The score of every finished match the caller may watch (newest 200), by submission id,
    for the matches pages: ``{"red", "blue"}`` (the teams), ``score``, ``shootout`` (null
    without one) and ``winner`` (red, blue, draw or null), as the service recorded them from
    the match's ``results.json``. A match without a score (failed before it played) is left
    out."""
    rows = list(session.scalars(select(Submission).where(_visible(principal),
                                                         Submission.state == "done")
                                .order_by(Submission.seq.desc()).limit(LISTING_LIMIT)))
    recorded = stored_many(session, [row.id for row in rows])
    found: dict[str, dict[str, Any]] = {}
    for row in rows:
        result = recorded.get(row.id)
        if result is None or result.score is None:
            continue
        found[row.id] = {**_teams(session, row).as_json(), "score": result.score,
                         "shootout": result.shootout, "winner": result.winner}
    return found


def mount(app: FastAPI) -> None:
    app.include_router(results_router)  # before the viewer's routes under the same prefix
    mount_viewer(app, SubmissionResolver())
