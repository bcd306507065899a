"""The application factory: ``create_app(settings)`` builds the FastAPI app with its lifespan.

Nothing happens at import time. The lifespan opens the database (migrating it to the newest
schema), builds the match pool and starts the queue worker; it stops the worker on shutdown
(running matches go on in the pool and are picked up again by the next start).

Routers: every module named in :data:`ROUTER_MODULES` exposes ``mount(app)``, which includes its
``APIRouter`` (and static files, if any). A package adds its own module to that tuple; to require
a team token in it use ``service.require_team`` (see :mod:`service.deps`).
"""

from __future__ import annotations

import gc
import importlib
import logging
from collections.abc import AsyncIterator, Callable, Sequence
from contextlib import asynccontextmanager
from dataclasses import dataclass, field
from typing import Any

from fastapi import FastAPI, Request
from fastapi.exceptions import RequestValidationError
from fastapi.responses import JSONResponse
from sqlalchemy import Engine
from sqlalchemy.orm import Session, sessionmaker
from starlette.exceptions import HTTPException as StarletteHTTPException

from service.db import make_engine, migrate, session_factory
from service.errors import AuthError, ServiceError
from service.settings import Settings

log = logging.getLogger(__name__)

ROUTER_MODULES: tuple[str, ...] = (
    "service.routers.health",
    "service.routers.teams",
    "service.routers.submissions",
    "service.routers.operator",
    "service.routers.nodes",  # the match pool's machines (operators)
    "service.routers.everyone",  # whoami, the queue and the matches, each role what it may see
    "service.routers.league",  # the league table and rating histories
    "envs.http_api",  # the HTTP environment API (learning environments)
    "viewer.service_pages",  # the web front end: replays, live view, queue and standings pages
)


@dataclass(slots=True)
class Services:
    """What request handlers and the worker share; built by the lifespan."""

    settings: Settings
    engine: Engine
    sessions: sessionmaker[Session]
    pool: Any = None  # service.pool.MatchPool
    worker: Any = None  # service.worker.QueueWorker
    aftermatch: Any = None  # service.aftermatch.AfterMatch
    ladder: Any = None  # service.league_ladder.Ladder (when settings.ladder_interval_s > 0)
    preflight: Preflight | None = None
    queue: Any = None  # service.submissions.QueueBoard
    tokens: Any = None  # service.tokens.TokenCache
    status: Any = None  # service.statusboard.StatusBoard

    def slots(self) -> int:
        return int(self.pool.slots) if self.pool is not None else self.settings.match_slots

    def changed(self, submission_id: str | None = None) -> None:
        """This process changed one submission (or, without an id, the queue as a whole)."""
        if self.queue is not None:
            self.queue.invalidate()
        if self.status is not None:
            if submission_id is None:
                self.status.invalidate()
            else:
                self.status.forget(submission_id)
    extras: dict[str, Any] = field(default_factory=dict)


PoolFactory = Callable[[Settings], Any]
Preflight = Callable[[dict[str, Any], Settings], float]
"""(team file, settings) -> seconds taken; raises service.errors.PreflightFailed."""


def create_app(
    settings: Settings,
    *,
    pool_factory: PoolFactory | None = None,
    preflight: Preflight | None = None,
    start_worker: bool = True,
    router_modules: Sequence[str] = ROUTER_MODULES,
) -> FastAPI:
    """The service's app. ``pool_factory`` defaults to the local Docker pool and ``preflight``
    to :func:`service.preflight.run`; unit tests pass fakes. ``start_worker=False`` serves the
    API without starting matches."""

    @asynccontextmanager
    async def lifespan(app: FastAPI) -> AsyncIterator[None]:
        import anyio.to_thread

        # Request handlers run in this many threads: more only fight over the GIL.
        anyio.to_thread.current_default_thread_limiter().total_tokens = settings.threads
        settings.data_dir.mkdir(parents=True, exist_ok=True)
        engine = make_engine(settings.db_url)
        migrate(engine)
        checker = None
        if preflight is None:
            from service.preflight import PreflightChecker

            checker = PreflightChecker()
        from service.statusboard import StatusBoard
        from service.submissions import MatchTimes, QueueBoard
        from service.tokens import TokenCache
        from service.views import submission_view

        services = Services(settings=settings, engine=engine, sessions=session_factory(engine),
                            preflight=preflight or checker,
                            queue=QueueBoard(times=MatchTimes(
                                default_s=settings.expected_match_s)),
                            tokens=TokenCache(ttl_s=settings.token_cache_s))
        services.status = StatusBoard(render=lambda session, row, team: submission_view(
            session, row, settings, slots=services.slots(), queue=services.queue,
            team_name=team).model_dump_json().encode(), ttl_s=settings.status_board_s,
            also=[services.tokens.revalidate])
        services.status.start(services.sessions)
        app.state.services = services
        from service.pool import make_pool

        services.pool = (pool_factory or make_pool)(settings)
        if start_worker:
            from service.aftermatch import AfterMatch
            from service.worker import QueueWorker

            services.aftermatch = AfterMatch(services)
            services.aftermatch.start()
            services.worker = QueueWorker(services)
            services.worker.start()
            if settings.ladder_interval_s > 0:
                from service.league_ladder import Ladder

                services.ladder = Ladder(services)
                services.ladder.start()
        # Everything loaded so far lives as long as the process: kept out of the collector's
        # full passes, which would otherwise stop every request for tens of milliseconds.
        gc.collect()
        gc.freeze()
        try:
            yield
        finally:
            if services.ladder is not None:
                services.ladder.stop()
            if services.worker is not None:
                services.worker.stop()
            if services.aftermatch is not None:
                services.aftermatch.stop()
            services.status.stop()
            if checker is not None:
                checker.close()
            engine.dispose()

    app = FastAPI(
        title="hlvs-runner submission service",
        version="1",
        description="Test matches, team files, results and logs for the teams of a league.",
        lifespan=lifespan,
    )
    _install_error_handlers(app)

    from service.middleware import BodyLimit, StatusFastPath

    app.add_middleware(StatusFastPath)
    app.add_middleware(BodyLimit, max_bytes=settings.max_upload_bytes)
    for name in router_modules:
        importlib.import_module(name).mount(app)
    return app


def _install_error_handlers(app: FastAPI) -> None:
    @app.exception_handler(ServiceError)
    async def service_error(request: Request, exc: ServiceError) -> JSONResponse:
        body = {"error": exc.kind, "message": str(exc), **exc.fields()}
        headers = {"WWW-Authenticate": "Bearer"} if isinstance(exc, AuthError) else None
        if exc.status_code >= 500:
            log.error("%s %s: %s", request.method, request.url.path, exc)
        return JSONResponse(body, status_code=exc.status_code, headers=headers)

    @app.exception_handler(RequestValidationError)
    async def validation_error(request: Request, exc: RequestValidationError) -> JSONResponse:
        problems = []
        for error in exc.errors():
            location = [str(part) for part in error.get("loc", ())]
            pointer = "/" + "/".join(location[1:]) if len(location) > 1 else "/"
            problems.append({"where": location[0] if location else "body",
                             "pointer": pointer, "message": str(error.get("msg", "")),
                             "type": str(error.get("type", ""))})
        summary = "; ".join(f"{p['where']} {p['pointer']}: {p['message']}" for p in problems)
        return JSONResponse({"error": "invalid_input", "message": summary, "problems": problems},
                            status_code=422)

    @app.exception_handler(StarletteHTTPException)
    async def http_error(request: Request, exc: StarletteHTTPException) -> JSONResponse:
        kind = {404: "not_found", 405: "method_not_allowed", 413: "too_large",
                415: "unsupported_media_type"}.get(exc.status_code, "http_error")
        return JSONResponse({"error": kind, "message": str(exc.detail)},
                            status_code=exc.status_code)


__all__ = ["ROUTER_MODULES", "Services", "create_app"]
