"""``/v1/operator``: the queue (pause, resume, requeue an infrastructure failure), teams, and
the tournament schedule's matches and standings. Operator tokens only."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from fastapi import APIRouter, FastAPI, Request
from pydantic import BaseModel
from sqlalchemy import select

from service import submissions
from service.db import ACTIVE_STATES, Submission, SubmissionState, Team
from service.deps import AppServices, DbSession, OperatorPrincipal, SessionRoute, get_services
from service.errors import Conflict, NotFound
from service.views import SubmissionView, view_of

router = APIRouter(prefix="/v1/operator", tags=["operator"], route_class=SessionRoute)


class QueueView(BaseModel):
    paused: bool
    slots: int
    active: list[SubmissionView]


class TeamSummary(BaseModel):
    name: str
    email: str | None
    accepts_friendlies: bool


class ScheduleView(BaseModel):
    name: str = ""  # the tournament's
    matches: list[dict[str, Any]]
    standings: list[dict[str, Any]]


def _slots(request: Request) -> int:
    services = get_services(request)
    return services.pool.slots if services.pool is not None else services.settings.match_slots


def _queue(request: Request, session: DbSession) -> QueueView:
    rows = session.scalars(select(Submission).where(Submission.state.in_(
        [s.value for s in ACTIVE_STATES])).order_by(Submission.seq))
    return QueueView(paused=submissions.queue_paused(session), slots=_slots(request),
                     active=[view_of(request, session, r) for r in rows])


@router.get("/queue")
def get_queue(request: Request, principal: OperatorPrincipal, session: DbSession) -> QueueView:
    return _queue(request, session)


@router.post("/queue/pause")
def pause_queue(request: Request, principal: OperatorPrincipal,
                session: DbSession) -> QueueView:
    """No new match starts until resumed; running ones go on; status says why it waits."""
    submissions.set_queue_paused(session, True)
    session.commit()
    get_services(request).changed()
    return _queue(request, session)


@router.post("/queue/resume")
def resume_queue(request: Request, principal: OperatorPrincipal,
                 session: DbSession) -> QueueView:
    submissions.set_queue_paused(session, False)
    session.commit()
    get_services(request).changed()
    worker = get_services(request).worker
    if worker is not None:
        worker.wake()
    return _queue(request, session)


@router.post("/submissions/{submission_id}/requeue", responses={
    409: {"description": "not a failure on the league's side, or the team has another "
                         "active test match"}})
def requeue(submission_id: str, request: Request, principal: OperatorPrincipal,
            session: DbSession) -> SubmissionView:
    """Queue a submission that failed on the league's side again, at its old place and
    uncharged."""
    row = session.scalar(select(Submission).where(Submission.id == submission_id)
                         .with_for_update())
    if row is None:
        raise NotFound(what="submission", ident=submission_id)
    if row.state != SubmissionState.FAILED.value or row.failure_side != "league":
        raise Conflict(f"submission {row.id} is {row.state}"
                       + (f" ({row.failure_class})" if row.failure_class else "")
                       + "; only failures on the league's side are requeued")
    submissions.refuse_if_active(session, row.team_id)
    row.state = SubmissionState.QUEUED.value
    row.cause = f"requeued by an operator after: {row.cause}"
    row.failure_class = row.failure_side = None
    row.finished_at = None
    row.pool_handle = None
    row.pool_detail = None
    row.video_state = row.video_detail = None  # the next attempt makes its own
    row.delivery_state = row.delivery_detail = None
    row.charged = False
    row.cancel_requested = False
    session.commit()
    get_services(request).changed()
    worker = get_services(request).worker
    if worker is not None:
        worker.wake()
    return view_of(request, session, row)


@router.get("/teams")
def list_teams(principal: OperatorPrincipal, session: DbSession) -> list[TeamSummary]:
    return [TeamSummary(name=t.name, email=t.email, accepts_friendlies=t.accepts_friendlies)
            for t in session.scalars(select(Team).order_by(Team.name))]


@router.get("/schedule")
def get_schedule(services: AppServices, principal: OperatorPrincipal) -> ScheduleView:
    """The tournament's matches (state, times, results) and the standings, read from the
    schedule's state file (``HLVS_SERVICE_SCHEDULE_STATE``)."""
    from orchestrator.config import load_schedule
    from tournament import Ledger, standings

    state = services.settings.schedule_state
    if not state or not Path(state).is_file():
        raise NotFound(what="tournament schedule state",
                       ident=state or "(HLVS_SERVICE_SCHEDULE_STATE is not set)")
    ledger = Ledger(Path(state))
    rows = ledger.rows()
    schedule_path = ledger.get_meta("schedule")
    schedule = (load_schedule(schedule_path, text=ledger.get_meta("schedule_text"))
                if schedule_path else None)
    teams = [t.name for t in schedule.teams] if schedule is not None else []
    return ScheduleView(name=schedule.name if schedule else "",
                        matches=[r.as_dict() for r in rows], standings=[
        s.as_dict() for s in standings(rows, teams, seed=schedule.name if schedule else "")])


def mount(app: FastAPI) -> None:
    app.include_router(router)


__all__ = ["mount", "router"]
