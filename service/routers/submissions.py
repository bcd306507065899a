"""``/v1/submissions``: test matches of the calling team; status, cancel and downloads.

Another team's submission id answers 404 exactly like an unknown one, so ids do not leak.
"""

from __future__ import annotations

import json
import os
import re
import stat
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any

import anyio
import anyio.to_thread
from fastapi import APIRouter, Depends, FastAPI, Request
from fastapi.responses import FileResponse
from fastapi.security import HTTPAuthorizationCredentials
from pydantic import BaseModel
from sqlalchemy import select
from starlette.concurrency import run_in_threadpool
from starlette.responses import Response

from contracts import ContractError, MatchReport, MatchResults, files
from service import ladder, submissions, teamfiles
from service.aftermatch import PARTIAL_VIDEO_FILE
from service.db import ACTIVE_STATES, Submission
from service.deps import (
    AppServices,
    DbSession,
    SessionRoute,
    TeamPrincipal,
    bearer,
    get_services,
    require_team,
)
from service.errors import InvalidInput, NotFound, PreflightFailed
from service.matchfiles import OWN_COLOR
from service.views import (
    SubmissionCreate,
    SubmissionReport,
    SubmissionView,
    TeamRobot,
    submission_view,
    view_of,
)

if TYPE_CHECKING:
    from orchestrator.config import TeamConfig
    from service.services import Services
    from service.tokens import Principal

router = APIRouter(prefix="/v1/submissions", tags=["submissions"],
                   route_class=SessionRoute)
ACTIVE_VALUES = frozenset(state.value for state in ACTIVE_STATES)



class LogListing(BaseModel):
    team: list[str]
    public: list[str]


@router.post("", status_code=201, responses={
    409: {"description": "the team already has an active test match (its id is in the body)"},
    422: {"description": "invalid body, unknown opponent or failed pre-flight check"}})
async def create_submission(body: SubmissionCreate, request: Request, services: AppServices,
                            principal: TeamPrincipal) -> SubmissionView:
    """Check the team's images (pre-flight) and queue a test match.

    One pre-flight per team at a time (a second submission meanwhile waits for the first,
    without a thread), run in threads of their own: a slow registry never holds the threads
    that answer requests."""
    team_id = principal.team_id
    assert team_id is not None
    async with services.preflight_claims.claim(team_id):
        team, file_id, credentials = await run_in_threadpool(
            _before_preflight, services, team_id, body)
        assert services.preflight is not None
        limiter = services.preflight_limiter
        if limiter is None:
            limiter = services.preflight_limiter = anyio.CapacityLimiter(
                max(1, services.settings.threads))
        try:
            elapsed = await anyio.to_thread.run_sync(services.preflight, team,
                                                     services.settings, limiter=limiter)
        except PreflightFailed as failed:
            await run_in_threadpool(_refuse, services, file_id, failed.stage, failed.cause)
            raise
        except InvalidInput as invalid:  # a problem of the file that only the check found
            await run_in_threadpool(_refuse, services, file_id, "config", str(invalid))
            raise
        return await run_in_threadpool(_after_preflight, services, request, principal, body,
                                       file_id, credentials, elapsed)


def _before_preflight(services: Services, team_id: int, body: SubmissionCreate
                      ) -> tuple[TeamConfig, int, int | None]:
    """The checks made before the pre-flight: (the team, its file's id, its credentials'
    id); no connection is held during the pre-flight."""
    with services.sessions() as session, session.begin():
        submissions.check_opponent(session, team_id=team_id, opponent=body.opponent)
        submissions.refuse_if_active(session, team_id)
        team_file = teamfiles.get(session, team_id=team_id, kind="team_config",
                                  version=body.team_config_version)
        file_id, document = team_file.id, teamfiles.opened(team_file, services.sealer)
        credentials = teamfiles.newest_id(session, team_id=team_id, kind="credentials")
    return teamfiles.validated_team(document), file_id, credentials  # today's rules


def _refuse(services: Services, file_id: int, stage: str, cause: str) -> None:
    with services.sessions() as session, session.begin():
        teamfiles.refuse(session, teamfiles.get_by_id(session, file_id), stage=stage,
                         cause=cause)


def _after_preflight(services: Services, request: Request, principal: Principal,
                     body: SubmissionCreate, file_id: int, credentials: int | None,
                     elapsed: float) -> SubmissionView:
    assert principal.team_id is not None
    with services.sessions() as session:
        with session.begin():
            row = submissions.create(session, team_id=principal.team_id,
                                     opponent=body.opponent, team_file_id=file_id,
                                     credentials_file_id=credentials, preflight_s=elapsed)
        services.changed(row.id)
        if services.worker is not None:
            services.worker.wake()
        with session.begin():
            view = view_of(request, session, row, principal.team_name)
    services.status.put(row.id, principal.team_id, view.model_dump_json().encode())
    return view


@router.get("")
def list_submissions(request: Request, principal: TeamPrincipal,
                     session: DbSession) -> list[SubmissionView]:
    rows = session.scalars(select(Submission).where(Submission.team_id == principal.team_id)
                           .order_by(Submission.seq.desc()).limit(100))
    return [view_of(request, session, r, principal.team_name) for r in rows]


@router.get("/{submission_id}", response_model=SubmissionView)
async def get_submission(
    submission_id: str, services: AppServices,
    credentials: Annotated[HTTPAuthorizationCredentials | None, Depends(bearer)],
) -> Response:
    """The submission's state; while queued its position, expected start and the reason it
    waits. A poll is answered from the status board when it can be (see
    :mod:`service.statusboard` and :class:`service.middleware.StatusFastPath`); here from the
    database."""
    presented = credentials.credentials if credentials is not None else None
    body = await run_in_threadpool(_status_body, services, presented, submission_id)
    return Response(body, media_type="application/json")


def _status_body(services: Services, presented: str | None, submission_id: str) -> bytes:
    with services.sessions() as session:
        token_cached = services.tokens.cached(presented) is not None
        principal = require_team(services.tokens.verify(session, presented))
        assert principal.team_id is not None
        row = submissions.get_own(session, team_id=principal.team_id,
                                  submission_id=submission_id)
        body = submission_view(session, row, services.settings, slots=services.slots(),
                               queue=services.queue,
                               team_name=principal.team_name).model_dump_json().encode()
        session.commit()
        if row.state in ACTIVE_VALUES or not token_cached:
            services.status.missed()  # the next polls find it (and the cached tokens renewed)
        return body


@router.post("/{submission_id}/cancel", responses={
    409: {"description": "the submission has already ended"}})
def cancel_submission(submission_id: str, request: Request, services: AppServices,
                      principal: TeamPrincipal, session: DbSession) -> SubmissionView:
    """Queued: cancelled at once and not charged. Running: stopped gracefully (the state
    becomes ``cancelled`` once the match has stopped and its logs are collected)."""
    assert principal.team_id is not None
    row = submissions.get_own(session, team_id=principal.team_id, submission_id=submission_id,
                              for_update=True)
    submissions.cancel(session, row)
    session.commit()
    services.changed(row.id)
    if services.worker is not None:
        services.worker.wake()
    return view_of(request, session, row, principal.team_name)


# downloads -------------------------------------------------------------------------------
def _match_dir(request: Request, row: Submission) -> Path:
    services = get_services(request)
    if row.pool_handle is None or services.pool is None:
        raise NotFound(what="match output of submission", ident=row.id)
    out: Path = services.pool.results_dir(row.pool_handle)
    return out


def _own(request: Request, principal: TeamPrincipal, session: Any, submission_id: str
         ) -> tuple[Submission, Path]:
    assert principal.team_id is not None
    row = submissions.get_own(session, team_id=principal.team_id, submission_id=submission_id)
    return row, _match_dir(request, row)


def _file(path: Path, what: str, row: Submission, media_type: str) -> FileResponse:
    if not path.is_file():
        raise NotFound(what=what, ident=f"{row.id} ({row.state})")
    return FileResponse(path, media_type=media_type, filename=path.name)


@router.get("/{submission_id}/report")
def get_report(submission_id: str, request: Request, principal: TeamPrincipal,
               session: DbSession) -> SubmissionReport:
    """The match's ``report.json`` with whose side a failure was on (``backend_error`` is true
    when it was the league's), the exit codes of the team's own robots and
    ``user_returncode`` (the first non-zero one, 0 when all exited 0, null when unknown or
    on a backend error)."""
    assert principal.team_id is not None
    row = submissions.get_own(session, team_id=principal.team_id, submission_id=submission_id)
    match_report: MatchReport | None = None
    robots: dict[str, TeamRobot] = {}
    if row.pool_handle is not None:
        out = _match_dir(request, row)
        try:
            match_report = MatchReport.load(out / files.REPORT)
        except ContractError:
            pass  # not written yet, or unreadable: the submission's own state says enough
        try:
            results = MatchResults.load(out / files.RESULTS)
        except ContractError:
            results = None
        for key, robot in (results.robots if results is not None else {}).items():
            if key.startswith(OWN_COLOR + "-"):
                robots[key] = TeamRobot(
                    image=robot.image, exit_code=robot.exit_code, oom_killed=robot.oom_killed,
                    image_error=robot.image_error, startup_error=robot.startup_error,
                    exited_during_game=robot.exited_during_game)
    codes = [r.exit_code for r in robots.values()]
    user_returncode = None
    if codes and all(isinstance(c, int) for c in codes) and row.failure_side != "league":
        user_returncode = next((c for c in codes if c != 0), 0)
    return SubmissionReport(
        submission=row.id, state=row.state, match_id=row.match_id,
        user_returncode=user_returncode,
        status="success" if row.state == "done" else row.state,
        failure_class=row.failure_class, failure_side=row.failure_side,
        backend_error=row.failure_side == "league", cause=row.cause,
        charged=row.charged, team_robots=robots,
        match_report=match_report.to_dict() if match_report is not None else None,
    )


@router.get("/{submission_id}/results")
def get_results(submission_id: str, request: Request, principal: TeamPrincipal,
                session: DbSession) -> Response:
    """The match's ``results.json`` as the team may see it: the other side's robots without
    their image, digest, container and errors (another team's images are its own; an operator
    reads the file itself)."""
    row, out = _own(request, principal, session, submission_id)
    path = out / files.RESULTS
    if not path.is_file():
        raise NotFound(what="results of submission", ident=f"{row.id} ({row.state})")
    return Response(json.dumps(own_view_of_results(json.loads(path.read_text("utf-8"))),
                               indent=2) + "\n", media_type="application/json")


OTHER_SIDE_HIDDEN = ("image", "digest", "image_error", "startup_error", "container",
                     "log_folder")


def own_view_of_results(results: dict[str, Any]) -> dict[str, Any]:
    """``results.json`` without the other side's image names and digests: its robots'
    identifying fields are null, and a cause, forfeit reason or warning that names one of its
    images says only that it was the other team's."""
    robots = results.get("robots")
    if not isinstance(robots, dict):
        return results
    secrets_of_other: set[str] = set()
    kept: dict[str, Any] = {}
    for key, robot in robots.items():
        if key.startswith(OWN_COLOR + "-") or not isinstance(robot, dict):
            kept[key] = robot
            continue
        for name in ("image", "digest"):
            value = robot.get(name)
            if isinstance(value, str) and value:
                secrets_of_other.add(value)
                repository = value.split("@", 1)[0]
                if ":" in repository.split("/")[-1]:
                    repository = repository.rpartition(":")[0]
                if "/" in repository:
                    secrets_of_other.add(repository)
        kept[key] = {**robot, **{name: None for name in OTHER_SIDE_HIDDEN if name in robot}}
    view = {**results, "robots": kept}

    def hidden(text: object) -> object:
        if isinstance(text, str) and any(s and s in text for s in secrets_of_other):
            return "(about the other team's images: not shown)"
        return text

    for name in ("failure", "forfeit"):
        entry = view.get(name)
        if isinstance(entry, dict):
            view[name] = {k: hidden(v) for k, v in entry.items()}
    if isinstance(view.get("warnings"), list):
        view["warnings"] = [hidden(w) for w in view["warnings"]]
    return view


@router.get("/{submission_id}/replay")
def get_replay(submission_id: str, request: Request, principal: TeamPrincipal,
               session: DbSession) -> FileResponse:
    row, out = _own(request, principal, session, submission_id)
    return _file(out / "public" / files.REPLAY, "replay of submission", row,
                 "application/octet-stream")


@router.get("/{submission_id}/video")
def get_video(submission_id: str, request: Request, principal: TeamPrincipal,
              session: DbSession) -> FileResponse:
    """The match's video (``video.state`` in the status says whether it is ready yet)."""
    row, out = _own(request, principal, session, submission_id)
    if row.video_state != "ready":
        raise NotFound(what="video of submission", ident=f"{row.id} (video "
                       f"{row.video_state or 'none: the match did not play'}"
                       + (f": {row.video_detail})" if row.video_detail else ")"))
    return _file(out / "public" / files.VIDEO, "video of submission", row, "video/mp4")


def _listing(root: Path) -> list[str]:
    """Every finished regular file under ``root`` (not a symlink, nor a file under a linked
    folder; a video still being rendered is not one). A name that is not UTF-8 (a robot may
    write any bytes) is listed with its bytes escaped as ``\\xNN`` (:func:`_unescaped` reads
    it back)."""
    if not root.is_dir():
        return []
    names = []
    for path in root.rglob("*"):
        if path.name == PARTIAL_VIDEO_FILE or not stat.S_ISREG(path.lstat().st_mode):
            continue
        relative = path.relative_to(root)
        if any(parent.is_symlink() for parent in (root / relative).parents
               if parent != root and parent.is_relative_to(root)):
            continue
        names.append(_escaped(relative))
    return sorted(names)


def _escaped(relative: Path) -> str:
    text = str(relative)
    try:
        text.encode("utf-8")
    except UnicodeEncodeError:
        return os.fsencode(relative).decode("utf-8", "backslashreplace")
    return text


_ESCAPE = re.compile(rb"\\x([0-9a-f]{2})")


def _unescaped(name: str) -> str:
    """A listed name back to the file's own name (its ``\\xNN`` escapes as bytes)."""
    if "\\x" not in name:
        return name
    raw = _ESCAPE.sub(lambda m: bytes([int(m.group(1), 16)]), name.encode("utf-8"))
    return os.fsdecode(raw)


@router.get("/{submission_id}/logs")
def list_logs(submission_id: str, request: Request, principal: TeamPrincipal,
              session: DbSession) -> LogListing:
    """The team's own logs (its robots' stdout/stderr and /robocup-logs) and the public logs;
    download one with ``/logs/team/<path>`` or ``/logs/public/<path>``. The opponent in a
    friendly the ladder scheduled reads its own robots' logs (blue) here too."""
    _, out, color = _logs_of(request, principal, session, submission_id)
    return LogListing(team=_listing(out / "teams" / color), public=_listing(out / "public"))


def _logs_of(request: Request, principal: TeamPrincipal, session: Any, submission_id: str
             ) -> tuple[Submission, Path, str]:
    assert principal.team_id is not None
    row, color = ladder.logs_side(session, team_id=principal.team_id,
                                  team_name=principal.team_name, submission_id=submission_id)
    return row, _match_dir(request, row), color


@router.get("/{submission_id}/logs/{part}/{path:path}")
def get_log(submission_id: str, part: str, path: str, request: Request,
            principal: TeamPrincipal, session: DbSession) -> FileResponse:
    _, out, color = _logs_of(request, principal, session, submission_id)
    roots = {"team": out / "teams" / color, "public": out / "public"}
    if part not in roots:
        raise NotFound(what="log folder", ident=part)
    root = roots[part].resolve()
    target = (root / path).resolve()
    if not target.is_file() and "\\x" in path:
        target = (root / _unescaped(path)).resolve()
    if not target.is_relative_to(root) or not target.is_file() or \
            target.name == PARTIAL_VIDEO_FILE:
        raise NotFound(what="log file", ident=f"{part}/{path}")
    return FileResponse(target, media_type="application/octet-stream",
                        filename=_escaped(Path(target.name)))


def mount(app: FastAPI) -> None:
    app.include_router(router)


__all__ = ["mount", "router"]
