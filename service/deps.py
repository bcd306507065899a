"""FastAPI dependencies: the database session per request and the caller's token.

Routers of other packages require a team token with::

    from service import TeamPrincipal
    @router.get("/v1/envs")
    def list_envs(principal: TeamPrincipal) -> ...:   # principal.team_id, .team_name

(``TeamPrincipal`` is ``Annotated[Principal, Depends(require_team)]``; for a whole router:
``APIRouter(dependencies=[Depends(require_team)])``.) ``OperatorPrincipal`` /
``require_operator`` admit operator tokens only; ``require_token`` admits both.
"""

from __future__ import annotations

import functools
import inspect
from collections.abc import Callable, Iterator
from typing import Annotated, Any

from fastapi import Depends, Request
from fastapi.routing import APIRoute
from fastapi.security import HTTPAuthorizationCredentials, HTTPBearer
from sqlalchemy.orm import Session

from service import tokens
from service.db import Scope
from service.errors import AuthError
from service.services import Services

bearer = HTTPBearer(auto_error=False, description="a team or operator token: hlvs_<id>_<secret>")


def get_services(request: Request) -> Services:
    """The app's :class:`service.services.Services` (built by its lifespan); a handler takes it as
    ``services: AppServices``."""
    services: Services = request.app.state.services
    return services


AppServices = Annotated[Services, Depends(get_services)]


def get_db(request: Request) -> Iterator[Session]:
    """One session per request. Handlers that write call ``session.commit()`` before they
    return (FastAPI may finish this dependency after the response is sent, so a client could
    otherwise read before the write lands); anything left is committed here, and an error
    rolls back."""
    factory = get_services(request).sessions
    with factory() as session:
        try:
            yield session
            session.commit()
        except BaseException:
            session.rollback()
            raise


DbSession = Annotated[Session, Depends(get_db)]


class SessionRoute(APIRoute):
    """A route whose handler ends its database transaction as it returns, in its own thread.

    Without it a handler that read after its last commit would return with a transaction
    open (on SQLite a write lock: every transaction begins IMMEDIATE) until FastAPI has
    validated the answer, which takes one of the request threads; with every thread waiting
    for that lock, nothing moved until SQLite's busy timeout answered 500 "database is
    locked". The service's routers use it (``APIRouter(route_class=SessionRoute)``)."""

    def __init__(self, path: str, endpoint: Callable[..., Any], **kwargs: Any) -> None:
        super().__init__(path, _ending_transactions(endpoint), **kwargs)


def _ending_transactions(endpoint: Callable[..., Any]) -> Callable[..., Any]:
    if inspect.iscoroutinefunction(endpoint):
        return endpoint  # an async handler uses its sessions in threads of its own

    @functools.wraps(endpoint)
    def ended(*args: Any, **kwargs: Any) -> Any:
        sessions = [v for v in kwargs.values() if isinstance(v, Session)]
        try:
            result = endpoint(*args, **kwargs)
        except BaseException:
            for session in sessions:
                session.rollback()
            raise
        for session in sessions:
            if session.in_transaction():
                session.commit()
        return result

    return ended


def require_token(
    request: Request,
    session: DbSession,
    credentials: Annotated[HTTPAuthorizationCredentials | None, Depends(bearer)],
) -> tokens.Principal:
    presented = credentials.credentials if credentials is not None else None
    cache = get_services(request).tokens
    principal = cache.verify(session, presented) if cache else tokens.verify(session, presented)
    session.commit()  # gives the connection back: a handler may read a body or wait first
    return principal


def require_team(
    principal: Annotated[tokens.Principal, Depends(require_token)],
) -> tokens.Principal:
    """The principal when it is a team's (usable as a plain function too)."""
    if principal.scope is not Scope.TEAM or principal.team_id is None:
        raise AuthError("scope", "this endpoint needs a team token (this one is an "
                        f"{principal.scope.value} token)")
    return principal


def require_operator(
    principal: Annotated[tokens.Principal, Depends(require_token)],
) -> tokens.Principal:
    if principal.scope is not Scope.OPERATOR:
        raise AuthError("scope", "this endpoint needs an operator token (this one is a "
                        f"{principal.scope.value} token)")
    return principal


TeamPrincipal = Annotated[tokens.Principal, Depends(require_team)]
OperatorPrincipal = Annotated[tokens.Principal, Depends(require_operator)]

__all__ = [
    "AppServices",
    "DbSession",
    "OperatorPrincipal",
    "SessionRoute",
    "TeamPrincipal",
    "get_db",
    "bearer",
    "get_services",
    "require_operator",
    "require_team",
    "require_token",
]
