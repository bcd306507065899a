"""The application factory: ``create_app(settings)`` builds the FastAPI app with its lifespan.

Nothing happens at import time. The lifespan opens the database (migrating it to the newest
schema), builds the match pool and starts the queue worker; it stops the worker on shutdown
(running matches go on in the pool and are picked up again by the next start).

Routers: each router module exposes ``mount(app)``, which includes its ``APIRouter`` (and static
files, if any). The service's own are :func:`service_routers`; a package above the service (the
pages, the environment API) hands its ``mount`` in ``mounts``, wired by :mod:`hlvs.app`; to
require a team token in it use ``service.require_team`` (see :mod:`service.deps`).
"""

from __future__ import annotations

import gc
import logging
from collections.abc import AsyncIterator, Callable, Sequence
from contextlib import asynccontextmanager
from typing import TYPE_CHECKING

from fastapi import FastAPI, Request
from fastapi.exceptions import RequestValidationError
from fastapi.responses import JSONResponse
from sqlalchemy.exc import DBAPIError
from starlette.exceptions import HTTPException as StarletteHTTPException

from cluster import MatchPool, PoolError, make_pool
from service.db import (
    UNAVAILABLE_RETRY_S,
    database_busy,
    database_unavailable,
    session_factory,
)
from service.errors import AuthError, ServiceError
from service.services import PoolFactory, Preflight, Services
from service.settings import Settings, open_data_dir, open_database

if TYPE_CHECKING:
    from sqlalchemy.engine import Engine

    from service.sealing import Sealer

log = logging.getLogger(__name__)

Mount = Callable[[FastAPI], None]
"""``mount(app)`` of a router module: includes its ``APIRouter`` in the app."""

def service_routers() -> tuple[Mount, ...]:
    """The service's own routers, in the order they are mounted (imported when an app is built:
    they import the service's modules, which import this one for :class:`Services`)."""
    from service.routers import (
        envs,
        everyone,
        health,
        ladder,
        nodes,
        operator,
        submissions,
        teams,
    )

    return (
        health.mount,
        teams.mount,
        submissions.mount,
        operator.mount,
        nodes.mount,  # the match pool's machines (operators)
        everyone.mount,  # whoami, the queue and the matches, each role what it may see
        envs.mount,  # the HTTP environment API (learning environments)
        ladder.mount,  # the league table of ratings
    )


def _start_threads(services: Services) -> None:
    """Start the service's threads, each given the parts it uses: the after-match work, the
    queue worker (which wakes it) and the ladder (which wakes the worker)."""
    from service.aftermatch import AfterMatch
    from service.ladder import LadderThread
    from service.worker import QueueWorker

    settings, sessions = services.settings, services.sessions
    services.aftermatch = AfterMatch(settings=settings, sessions=sessions, pool=services.pool,
                                     sealer=services.sealer)
    services.aftermatch.start()
    services.worker = QueueWorker(settings=settings, pool=services.pool, sessions=sessions,
                                  sealer=services.sealer, changed=services.changed,
                                  aftermatch=services.aftermatch)
    services.worker.start()
    services.ladder_thread = LadderThread(settings=settings, sessions=sessions,
                                          cache=services.ladder, changed=services.changed,
                                          slots=services.slots, worker=services.worker)
    services.ladder_thread.start()


def create_app(
    settings: Settings,
    *,
    pool_factory: PoolFactory | None = None,
    preflight: Preflight | None = None,
    start_worker: bool = True,
    mounts: Sequence[Mount] = (),
    storage: tuple[Engine, Sealer] | None = None,
) -> FastAPI:
    """The service's app. ``pool_factory`` defaults to the local Docker pool and ``preflight``
    to :func:`service.preflight.run`; unit tests pass fakes. ``start_worker=False`` serves the
    API without starting matches. ``mounts`` adds routers of packages above the service (see
:func:`hlvs.app.create_app`, which adds the pages and the environment API). ``storage``: what
:func:`open_storage` opened before the server started, used by the first start instead of
opening it again."""
    opened = [storage] if storage is not None else []

    @asynccontextmanager
    async def lifespan(app: FastAPI) -> AsyncIterator[None]:
        import anyio.to_thread

        # Request handlers run in this many threads: more only fight over the GIL.
        anyio.to_thread.current_default_thread_limiter().total_tokens = settings.threads
        engine, sealer = opened.pop() if opened else open_storage(settings)
        checker = None
        if preflight is None:
            from service.preflight import PreflightChecker

            checker = PreflightChecker()
            checker.reclaim()  # what checks of a killed service process left
        from service.statusboard import StatusBoard
        from service.submissions import MatchTimes, QueueBoard
        from service.tokens import TokenCache
        from service.views import submission_view

        queue = QueueBoard(times=MatchTimes(default_s=settings.expected_match_s))
        tokens = TokenCache(ttl_s=settings.token_cache_s)
        status = StatusBoard(render=lambda session, row, team: submission_view(
            session, row, settings, slots=services.slots(), queue=queue,
            team_name=team).model_dump_json().encode(), ttl_s=settings.status_board_s,
            also=[tokens.revalidate])
        services = Services(settings=settings, engine=engine, sessions=session_factory(engine),
                            pool=(pool_factory or pool_from_settings)(settings),
                            preflight=preflight or checker, queue=queue, tokens=tokens,
                            status=status, sealer=sealer)
        status.start(services.sessions)
        app.state.services = services
        if start_worker:
            _start_threads(services)
        # Everything loaded so far lives as long as the process: kept out of the collector's
        # full passes, which would otherwise stop every request for tens of milliseconds.
        gc.collect()
        gc.freeze()
        try:
            yield
        finally:
            _stop(services)
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
    for mount in (*service_routers(), *mounts):
        mount(app)
    return app


def open_storage(settings: Settings) -> tuple[Engine, Sealer]:
    """The private data and match folders, the sealer of stored secrets, and the database
    migrated to this version (secrets an older version stored in the clear sealed). ``hlvs
    serve`` opens it before the server starts (and hands it to :func:`create_app`), so that a
    wrong key or an unreachable database is one line naming the setting, not a traceback in
    the server's startup log."""
    from service.db import transaction
    from service.sealing import key_file, load_sealer
    from service.teamfiles import seal_stored

    open_data_dir(settings)  # 0700; the files below it are 0600
    sealer = load_sealer(
        key=settings.secret_key, key_path=key_file(settings.data_dir, settings.secret_key_file)
    )
    engine = open_database(settings)
    with transaction(session_factory(engine)) as session:
        seal_stored(session, sealer)  # secrets stored in the clear by an older version
    return engine, sealer


def _stop(services: Services) -> None:
    """Stop the service's threads: the ladder, the worker, the after-match work, the status
    board."""
    if services.ladder_thread is not None:
        services.ladder_thread.stop()
    if services.worker is not None:
        services.worker.stop()
    if services.aftermatch is not None:
        services.aftermatch.stop()
    services.status.stop()


def pool_from_settings(settings: Settings) -> MatchPool:
    """The match pool that the settings name (``HLVS_SERVICE_POOL``: local or slurm)."""
    return make_pool(kind=settings.pool, slots=settings.match_slots,
                     slurm_conf=settings.slurm_conf or None)


def _install_error_handlers(app: FastAPI) -> None:
    @app.exception_handler(PoolError)
    async def pool_error(request: Request, exc: PoolError) -> JSONResponse:
        log.error("%s %s: %s", request.method, request.url.path, exc)
        body = {"error": exc.kind, "message": str(exc), **exc.fields()}
        return JSONResponse(body, status_code=503)

    @app.exception_handler(DBAPIError)
    async def database_error(request: Request, exc: DBAPIError) -> JSONResponse:
        """A database too busy to answer in time (SQLite's lock past its busy timeout, a
        PostgreSQL lock or serialization failure), or one that cannot be reached (PostgreSQL
        restarting, stopped or unreachable: the connection refused, closed or timed out) is a
        503 to retry, never a 500."""
        log.error("%s %s: database error: %s", request.method, request.url.path, exc.orig)
        if database_busy(exc):
            return JSONResponse({"error": "busy", "message": "the database is busy; try "
                                 "again in a moment"}, status_code=503,
                                headers={"Retry-After": "1"})
        if database_unavailable(exc):
            return JSONResponse({"error": "unavailable", "message": "the database cannot be "
                                 "reached; try again in a moment"}, status_code=503,
                                headers={"Retry-After": str(UNAVAILABLE_RETRY_S)})
        return JSONResponse({"error": "internal", "message": "database error"},
                            status_code=500)

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

    @app.exception_handler(UnicodeEncodeError)
    async def not_text(request: Request, exc: UnicodeEncodeError) -> JSONResponse:
        """A string of the body with a lone surrogate (valid JSON, not text) is refused."""
        message = "a lone surrogate (\\ud800-\\udfff) in the body is not text"
        return JSONResponse({"error": "invalid_input", "message": message, "problems": [
            {"where": "body", "pointer": "/", "message": message,
             "expected": "text that is valid Unicode"}]}, status_code=422)

    @app.exception_handler(StarletteHTTPException)
    async def http_error(request: Request, exc: StarletteHTTPException) -> JSONResponse:
        if exc.status_code == 400 and isinstance(exc.__cause__, RecursionError):
            # the route's JSON parser gave up on the nesting: the same answer as a file upload
            from service.bodies import MAX_DEPTH, deep_pointer
            from service.middleware import BODY_KEY

            pointer = deep_pointer(b"".join(request.scope.get(BODY_KEY, ())), MAX_DEPTH) or "/"
            message = f"nested deeper than {MAX_DEPTH} levels"
            return JSONResponse({"error": "invalid_input", "message": f"body {pointer}: "
                                 f"{message}", "problems": [
                                     {"where": "body", "pointer": pointer, "message": message,
                                      "expected": f"at most {MAX_DEPTH} levels of nesting"}]},
                                status_code=422)
        kind = {404: "not_found", 405: "method_not_allowed", 413: "too_large",
                415: "unsupported_media_type"}.get(exc.status_code, "http_error")
        return JSONResponse({"error": kind, "message": str(exc.detail)},
                            status_code=exc.status_code)


__all__ = ["Services", "create_app", "pool_from_settings", "service_routers"]
