"""The parts of the running service, built by the app's lifespan (:func:`service.app.create_app`)
and shared by the request handlers: :class:`Services` (the service's threads are given only the
parts they use). This module imports none of the threads or routers, so that they need not
import the app."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Protocol

from sqlalchemy import Engine
from sqlalchemy.orm import Session, sessionmaker

from cluster import MatchPool
from orchestrator.config import TeamConfig
from service.ratings import LadderCache
from service.settings import Settings
from service.submissions import PreflightClaims

if TYPE_CHECKING:
    from anyio import CapacityLimiter

    from service.sealing import Sealer
    from service.statusboard import StatusBoard
    from service.submissions import QueueBoard
    from service.tokens import TokenCache


class Background(Protocol):
    """A thread of the service that waits for work (the queue worker, the after-match
    delivery); :meth:`wake` tells it there is some now."""

    def start(self) -> None: ...

    def wake(self) -> None: ...

    def stop(self) -> None: ...


@dataclass(slots=True, kw_only=True)
class Services:
    """What request handlers and the worker share; built by the lifespan (routers get it, or
    one of its parts, through the accessors of :mod:`service.deps`)."""

    settings: Settings
    engine: Engine
    sessions: sessionmaker[Session]
    pool: MatchPool  # the port: a local-Docker or Slurm pool, a fake in unit tests
    queue: QueueBoard
    tokens: TokenCache
    status: StatusBoard
    sealer: Sealer  # the secrets stored in the database
    preflight: Preflight | None = None
    worker: Background | None = None  # service.worker.QueueWorker; None when the app serves
    aftermatch: Background | None = None  # service.aftermatch.AfterMatch  without matches
    ladder_thread: Background | None = None  # service.ladder.LadderThread
    ladder: LadderCache = field(default_factory=LadderCache)  # the table the pages answer
    # one pre-flight check per team at a time, and at most ``settings.threads`` at once (the
    # limiter is made in the event loop, by the first submission)
    preflight_claims: PreflightClaims = field(default_factory=PreflightClaims)
    preflight_limiter: CapacityLimiter | None = None

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


PoolFactory = Callable[[Settings], MatchPool]
Preflight = Callable[[TeamConfig, Settings], float]
"""(the submitted team, checked; settings) -> seconds taken; raises
service.errors.PreflightFailed."""


__all__ = ["Background", "PoolFactory", "Preflight", "Services"]
