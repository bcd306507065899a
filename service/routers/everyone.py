"""What every signed-in person may read, each role what it may see: who the token speaks for,
the queue (other teams' entries without their details for a team) and the matches (a team's
own and the friendlies it played as the opponent, every one for an operator).

``GET /v1/whoami``, ``/v1/queue``, ``/v1/matches``: any token (team or operator).
"""

from __future__ import annotations

from typing import Annotated

from fastapi import APIRouter, Depends, FastAPI, Request
from pydantic import BaseModel
from sqlalchemy import select

from service import submissions
from service.db import ACTIVE_STATES, Submission
from service.db.models import Scope
from service.deps import DbSession, SessionRoute, get_services, require_token
from service.results import stored_many
from service.tokens import Principal
from service.views import SubmissionView, view_of

router = APIRouter(prefix="/v1", tags=["everyone"], route_class=SessionRoute)
AnyPrincipal = Annotated[Principal, Depends(require_token)]
HIDDEN = "another team"
MATCH_LIST_LIMIT = 200


class WhoAmI(BaseModel):
    scope: str  # team | operator
    team: str | None


class QueueEntry(BaseModel):
    """One active match; ``own`` false: another team's, shown without its details."""

    own: bool
    position: int | None
    state: str
    team: str
    opponent: str
    id: str | None
    expected_start: str | None
    waiting_reason: str | None


class PublicQueue(BaseModel):
    paused: bool
    slots: int
    active: list[QueueEntry]


def _is_operator(principal: Principal) -> bool:
    return principal.scope is Scope.OPERATOR


@router.get("/whoami")
def whoami(principal: AnyPrincipal) -> WhoAmI:
    return WhoAmI(scope=principal.scope.value, team=principal.team_name)


@router.get("/queue")
def public_queue(request: Request, principal: AnyPrincipal, session: DbSession) -> PublicQueue:
    """The active matches in queue order; a team sees its own in full and the others' as
    "another team" (no id, opponent or reason), an operator sees all."""
    rows = session.scalars(select(Submission).where(Submission.state.in_(
        [s.value for s in ACTIVE_STATES])).order_by(Submission.seq))
    entries = []
    for row in rows:
        view = view_of(request, session, row)
        own = _is_operator(principal) or row.team_id == principal.team_id
        entries.append(QueueEntry(
            own=own, position=view.queue_position, state=view.state,
            team=view.team if own else HIDDEN, opponent=view.opponent if own else "-",
            id=view.id if own else None,
            expected_start=view.expected_start.isoformat() if view.expected_start else None,
            waiting_reason=view.waiting_reason if own else None))
    return PublicQueue(paused=submissions.queue_paused(session),
                       slots=get_services(request).slots(), active=entries)


@router.get("/matches")
def list_matches(request: Request, principal: AnyPrincipal,
                 session: DbSession) -> list[SubmissionView]:
    """A team's own matches (and friendlies it was the opponent in); every match for an
    operator; newest first, at most 200. An ended match's score, play and each side's figures
    are in ``result``, from the database (the match folder is not read)."""
    query = select(Submission).order_by(Submission.seq.desc()).limit(MATCH_LIST_LIMIT)
    if not _is_operator(principal):
        query = query.where((Submission.team_id == principal.team_id)
                            | (Submission.opponent == principal.team_name))
    rows = list(session.scalars(query))
    results = stored_many(session, [row.id for row in rows])  # one query for the scores
    views = []
    for row in rows:
        view = view_of(request, session, row, results=results)
        if not _is_operator(principal) and row.team_id != principal.team_id:
            view = as_opponent(view)
        views.append(view)
    return views


def as_opponent(view: SubmissionView) -> SubmissionView:
    """A friendly as its opponent sees it: without what is the asking team's own (where its
    logs go, its pre-flight, the cause of a failure on its side)."""
    return view.model_copy(update={
        "log_delivery": None, "preflight_s": None, "waiting_reason": None,
        "cause": view.cause if view.failure_side == "league" else None})


def mount(app: FastAPI) -> None:
    app.include_router(router)
