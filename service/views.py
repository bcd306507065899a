"""Response bodies shared by the routers (Pydantic models; the OpenAPI document comes from
them)."""

from __future__ import annotations

from collections.abc import Mapping
from datetime import datetime

from fastapi import Request
from pydantic import BaseModel, ConfigDict, Field
from sqlalchemy.orm import Session

from service.db import ACTIVE_STATES, Submission, Team, utc
from service.results import MatchSummary, SideResult, stored
from service.settings import Settings
from service.submissions import QueueBoard

ACTIVE_VALUES = frozenset(state.value for state in ACTIVE_STATES)


class Links(BaseModel):
    status: str
    report: str
    results: str
    logs: str
    replay: str
    video: str


class Product(BaseModel):
    """Work done after the match ended: its video, the delivery of the team's logs."""

    state: str = Field(description="pending | ready (video) | delivered (logs) | failed")
    detail: str | None


class MatchResultView(BaseModel):
    """The result of a finished match, as the service recorded it from its ``results.json``
    (the submitting team plays red, its opponent blue)."""

    score: dict[str, int] | None = Field(description="goals by colour (halves and extra time)")
    shootout: dict[str, int] | None = Field(description="penalty shoot-out goals by colour; "
                                            "null without a shoot-out")
    winner: str | None = Field(description="red | blue | draw")
    final_state: str | None
    halves_playing: list[int] | None = Field(description="halves that reached PLAYING; null "
                                             "when no football was played")
    playing_s: float | None = Field(description="simulated seconds in PLAYING")
    sim_time_ms: int | None
    real_time_factor: float | None
    teams: dict[str, SideResult] = Field(description="by colour: red, blue")


def result_view(summary: MatchSummary) -> MatchResultView:
    return MatchResultView(
        score=summary.score, shootout=summary.shootout, winner=summary.winner,
        final_state=summary.final_state,
        halves_playing=list(summary.halves_playing) if summary.halves_playing is not None
        else None, playing_s=summary.playing_s, sim_time_ms=summary.sim_time_ms,
        real_time_factor=summary.real_time_factor,
        teams=dict(summary.sides))


class SubmissionView(BaseModel):
    id: str
    team: str
    opponent: str
    state: str
    created_at: datetime
    started_at: datetime | None
    finished_at: datetime | None
    queue_position: int | None = Field(description="1 = next to start; only while queued")
    expected_start: datetime | None
    waiting_reason: str | None = Field(description="why it waits: in the service's queue, or "
                                       "in the cluster (e.g. Slurm's AssocGrpJobsLimit: the "
                                       "team's account runs a match already)")
    match_id: str | None
    attempts: int
    cancel_requested: bool
    charged: bool
    failure_class: str | None
    failure_side: str | None = Field(description="team | league, when it failed")
    cause: str | None
    preflight_s: float | None
    video: Product | None = Field(description="the match's video, rendered after it ended "
                                  "(download it from links.video when ready); null when the "
                                  "match did not play")
    log_delivery: Product | None = Field(description="the upload of the team's logs to the "
                                         "target of its credentials.json; null when the team "
                                         "had uploaded none when it submitted")
    result: MatchResultView | None = Field(
        default=None, description="the score, play and each side's figures of the ended match; "
        "null while it has not ended or when it left no results")
    links: Links


class TeamRobot(BaseModel):
    """What a team may see of its own robot in the match results."""

    image: str | None
    exit_code: int | None
    oom_killed: bool
    image_error: str | None
    startup_error: str | None
    exited_during_game: bool


class SubmissionReport(BaseModel):
    """``GET /v1/submissions/{id}/report``, saved as ``report.json`` by ``hlvs results``: the
    match's own report with whose side a failure was on (``backend_error`` is true when it was
    the league's) and ``user_returncode`` (the first non-zero exit code of the team's robots, 0
    when all exited 0, null when unknown or on a backend error)."""

    submission: str
    state: str
    match_id: str | None
    user_returncode: int | None
    status: str
    failure_class: str | None
    failure_side: str | None
    backend_error: bool
    cause: str | None
    charged: bool
    team_robots: dict[str, TeamRobot]
    match_report: dict[str, str | list[dict[str, str]]] | None = Field(
        description="the match's report.json as written (contracts.match_results.MatchReport)")


class SubmissionCreate(BaseModel):
    model_config = ConfigDict(extra="forbid")

    opponent: str = Field(default="stub", max_length=64,
                          description="'stub' or a team that accepts friendlies")
    team_config_version: int | None = Field(default=None, ge=1, le=2**31 - 1,
                                            description="default: the newest version")


def submission_view(session: Session, row: Submission, settings: Settings, *,
                    slots: int, queue: QueueBoard, team_name: str | None = None,
                    results: Mapping[str, MatchSummary] | None = None) -> SubmissionView:
    """The view of ``row``; its result from ``results`` (by submission id) when given, else
    looked up (only for an ended submission: the status board renders active ones)."""
    if results is not None:
        summary = results.get(row.id)
    else:
        summary = None if row.state in ACTIVE_VALUES else stored(session, row.id)
    if team_name is None:
        team = session.get(Team, row.team_id)
        team_name = team.name if team else "?"
    info = queue.info(session, row, slots=slots)
    base = f"/v1/submissions/{row.id}"
    return SubmissionView(
        id=row.id, team=team_name, opponent=row.opponent, state=row.state,
        created_at=utc(row.created_at),
        started_at=utc(row.started_at) if row.started_at else None,
        finished_at=utc(row.finished_at) if row.finished_at else None,
        queue_position=info.position, expected_start=info.expected_start,
        waiting_reason=info.reason or row.pool_detail, match_id=row.match_id, attempts=row.attempts,
        cancel_requested=row.cancel_requested, charged=row.charged,
        failure_class=row.failure_class, failure_side=row.failure_side, cause=row.cause,
        preflight_s=round(row.preflight_s, 2) if row.preflight_s is not None else None,
        video=Product(state=row.video_state, detail=row.video_detail)
        if row.video_state else None,
        log_delivery=Product(state=row.delivery_state, detail=row.delivery_detail)
        if row.delivery_state else None,
        result=result_view(summary) if summary is not None else None,
        links=Links(status=base, report=base + "/report", results=base + "/results",
                    logs=base + "/logs", replay=base + "/replay", video=base + "/video"),
    )


def view_of(request: Request, session: Session, row: Submission,
            team_name: str | None = None,
            results: Mapping[str, MatchSummary] | None = None) -> SubmissionView:
    """The view of ``row`` with the app's settings, pool slots and match-time cache."""
    from service.deps import get_services

    services = get_services(request)
    slots = services.pool.slots if services.pool is not None else services.settings.match_slots
    return submission_view(session, row, services.settings, slots=slots, queue=services.queue,
                           team_name=team_name, results=results)


__all__ = [
    "Links",
    "MatchResultView",
    "Product",
    "SideResult",
    "SubmissionCreate",
    "SubmissionReport",
    "SubmissionView",
    "TeamRobot",
    "result_view",
    "submission_view",
    "view_of",
]
