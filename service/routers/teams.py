"""``/v1/team``: the calling team, its notification settings and its files (in versions)."""

from __future__ import annotations

import json
from datetime import datetime
from typing import Annotated, Any

from fastapi import APIRouter, FastAPI, Request
from fastapi import Path as PathParam
from pydantic import BaseModel, ConfigDict, Field, HttpUrl
from starlette.concurrency import run_in_threadpool

from service import outbound, sealing, teamfiles
from service.bodies import read_json_body
from service.db import Team, utc
from service.deps import AppServices, DbSession, SessionRoute, TeamPrincipal
from service.errors import NotFound

router = APIRouter(prefix="/v1/team", tags=["team"], route_class=SessionRoute)


class TeamView(BaseModel):
    name: str
    email: str | None
    accepts_friendlies: bool
    webhook_url: str | None
    webhook_secret_set: bool


class TeamUpdate(BaseModel):
    model_config = ConfigDict(extra="forbid")

    email: str | None = Field(default=None, max_length=254, pattern=r"^[^@\s]+@[^@\s]+$")
    accepts_friendlies: bool | None = None
    webhook_url: HttpUrl | None = None
    webhook_secret: str | None = Field(default=None, min_length=16, max_length=128)


class Problem(BaseModel):
    file: str
    pointer: str
    message: str
    expected: str = ""
    suggestion: str = ""
    severity: str = "error"
    text: str = ""


class FileVersion(BaseModel):
    kind: str
    version: int
    sha256: str
    created_at: datetime
    problems: list[Problem]
    valid: bool = True  # False: it failed a pre-flight check and is never the current version


class FileContent(FileVersion):
    content: dict[str, Any]


class CheckResult(BaseModel):
    valid: bool
    problems: list[Problem]


def _view(team: Team) -> TeamView:
    return TeamView(name=team.name, email=team.email, accepts_friendlies=team.accepts_friendlies,
                    webhook_url=team.webhook_url, webhook_secret_set=bool(team.webhook_secret))


def _version(row: Any) -> FileVersion:
    return FileVersion(kind=row.kind, version=row.version, sha256=row.sha256,
                       created_at=utc(row.created_at),
                       problems=[Problem(**p) for p in json.loads(row.problems_json)],
                       valid=bool(row.valid))


@router.get("")
def get_team(principal: TeamPrincipal, session: DbSession) -> TeamView:
    team = session.get(Team, principal.team_id)
    assert team is not None
    return _view(team)


@router.patch("")
def update_team(body: TeamUpdate, services: AppServices, principal: TeamPrincipal,
                session: DbSession) -> TeamView:
    if body.webhook_url is not None:
        outbound.check_url(str(body.webhook_url), outbound.allowed_networks(services.settings),
                           field="/webhook_url")
    team = session.get(Team, principal.team_id)
    assert team is not None
    given = body.model_fields_set
    if "email" in given:
        team.email = body.email
    if "accepts_friendlies" in given and body.accepts_friendlies is not None:
        team.accepts_friendlies = body.accepts_friendlies
    if "webhook_url" in given:
        team.webhook_url = str(body.webhook_url) if body.webhook_url else None
    if "webhook_secret" in given:
        team.webhook_secret = (services.sealer.seal(body.webhook_secret)
                               if body.webhook_secret else None)
    session.commit()
    return _view(team)


@router.put("/files/{kind}", status_code=201, responses={
    413: {"description": "over the upload limit"}, 415: {"description": "not JSON"},
    422: {"description": "invalid: every problem as hlvs check finds it"}})
async def upload_file(kind: str, request: Request, services: AppServices,
                      principal: TeamPrincipal) -> FileVersion:
    """Check and store a new version of ``team_config`` or ``credentials`` (a JSON body)."""
    if kind not in teamfiles.KINDS:
        raise NotFound(what="file kind", ident=kind)
    document = await read_json_body(request, limit_bytes=services.settings.max_upload_bytes,
                                    name=teamfiles.KINDS[kind])
    def store() -> FileVersion:
        with services.sessions() as session, session.begin():
            assert principal.team_id is not None
            return _version(teamfiles.store(
                session, team_id=principal.team_id, kind=kind, document=document,
                sealer=services.sealer,
                allowed=outbound.allowed_log_networks(services.settings)))

    return await run_in_threadpool(store)


@router.post("/files/{kind}/check")
async def check_file(kind: str, request: Request, services: AppServices,
                     principal: TeamPrincipal) -> CheckResult:
    """Check a file without storing it."""
    if kind not in teamfiles.KINDS:
        raise NotFound(what="file kind", ident=kind)
    document = await read_json_body(request, limit_bytes=services.settings.max_upload_bytes,
                                    name=teamfiles.KINDS[kind])
    problems = teamfiles.check(kind, document,
                               allowed=outbound.allowed_log_networks(services.settings))
    return CheckResult(valid=not any(p["severity"] == "error" for p in problems),
                       problems=[Problem(**p) for p in problems])


@router.get("/files/{kind}")
def list_versions(kind: str, principal: TeamPrincipal, session: DbSession) -> list[FileVersion]:
    assert principal.team_id is not None
    if kind not in teamfiles.KINDS:
        raise NotFound(what="file kind", ident=kind)
    return [_version(r) for r in teamfiles.versions(session, team_id=principal.team_id,
                                                    kind=kind)]


@router.get("/files/{kind}/{version}")
def get_version(kind: str, version: Annotated[int, PathParam(ge=1, le=2**31 - 1)],
                principal: TeamPrincipal,
                session: DbSession) -> FileContent:
    """One stored version (``credentials`` are returned with their secrets masked)."""
    assert principal.team_id is not None
    row = teamfiles.get(session, team_id=principal.team_id, kind=kind, version=version)
    content = _masked(json.loads(row.content))
    return FileContent(**_version(row).model_dump(), content=content)


def _masked(value: Any) -> Any:
    """A stored file as shown back: every secret (sealed at rest) as ``***``."""
    if isinstance(value, dict):
        return {k: _masked(v) for k, v in value.items()}
    if isinstance(value, list):
        return [_masked(v) for v in value]
    return "***" if sealing.is_sealed(value) else value


def mount(app: FastAPI) -> None:
    app.include_router(router)
