"""Database layer: typed models, engine/session helpers, Alembic migrations."""

from __future__ import annotations

from service.db.models import (
    ACTIVE_STATES,
    Base,
    MediaState,
    Notification,
    Scope,
    ServiceFlag,
    Submission,
    SubmissionState,
    Team,
    TeamFile,
    Token,
    now,
    utc,
)
from service.db.session import (
    UNAVAILABLE_RETRY_S,
    database_busy,
    database_unavailable,
    make_engine,
    migrate,
    session_factory,
    transaction,
)

__all__ = [
    "ACTIVE_STATES",
    "Base",
    "MediaState",
    "Notification",
    "Scope",
    "ServiceFlag",
    "Submission",
    "SubmissionState",
    "Team",
    "TeamFile",
    "Token",
    "UNAVAILABLE_RETRY_S",
    "database_busy",
    "database_unavailable",
    "make_engine",
    "migrate",
    "now",
    "session_factory",
    "transaction",
    "utc",
]
