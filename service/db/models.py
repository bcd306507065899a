"""Tables of the service (SQLAlchemy 2.0 typed models). The schema is owned by Alembic
(``service/db/migrations``); change both together.

Times are stored in UTC; :func:`utc` gives back an aware datetime whatever the backend kept.
"""

from __future__ import annotations

import enum
from datetime import UTC, datetime

from sqlalchemy import (
    Boolean,
    DateTime,
    Float,
    ForeignKey,
    Index,
    Integer,
    String,
    Text,
    UniqueConstraint,
    text,
)
from sqlalchemy.orm import DeclarativeBase, Mapped, mapped_column


def now() -> datetime:
    return datetime.now(UTC)


def utc(value: datetime) -> datetime:
    """``value`` as an aware UTC datetime (SQLite returns naive ones)."""
    return value.replace(tzinfo=UTC) if value.tzinfo is None else value.astimezone(UTC)


class Base(DeclarativeBase):
    pass


class Scope(enum.StrEnum):
    TEAM = "team"
    OPERATOR = "operator"


class SubmissionState(enum.StrEnum):
    """QUEUED -> STARTING -> RUNNING -> DONE | FAILED | CANCELLED (QUEUED -> CANCELLED too).

    STARTING is written before the pool is asked to start the match, so a restart finds it and
    asks the pool whether it started; a lost start is queued again, never started twice.
    """

    QUEUED = "queued"
    STARTING = "starting"
    RUNNING = "running"
    DONE = "done"
    FAILED = "failed"
    CANCELLED = "cancelled"


class MediaState(enum.StrEnum):
    """Work done after a match ended (its video, the delivery of the team's logs): NULL in the
    database when there is none to do (the match never played; no credentials uploaded)."""

    PENDING = "pending"
    READY = "ready"  # the video
    DELIVERED = "delivered"  # the logs
    FAILED = "failed"


ACTIVE_STATES = (SubmissionState.QUEUED, SubmissionState.STARTING, SubmissionState.RUNNING)
_ACTIVE_SQL = "state IN ('queued', 'starting', 'running')"


class Team(Base):
    __tablename__ = "teams"

    id: Mapped[int] = mapped_column(Integer, primary_key=True)
    name: Mapped[str] = mapped_column(String(64), unique=True)
    email: Mapped[str | None] = mapped_column(String(254))
    accepts_friendlies: Mapped[bool] = mapped_column(Boolean, default=False)
    webhook_url: Mapped[str | None] = mapped_column(String(2000))
    webhook_secret: Mapped[str | None] = mapped_column(String(512))  # sealed
    slurm_account: Mapped[str | None] = mapped_column(String(64))  # made by service.accounts
    created_at: Mapped[datetime] = mapped_column(DateTime(timezone=True), default=now)


class Token(Base):
    """An API token: ``hlvs_<id>_<secret>``; only the SHA-256 of the secret is stored."""

    __tablename__ = "tokens"

    id: Mapped[str] = mapped_column(String(16), primary_key=True)
    team_id: Mapped[int | None] = mapped_column(ForeignKey("teams.id"))
    scope: Mapped[str] = mapped_column(String(16))
    secret_sha256: Mapped[str] = mapped_column(String(64))
    label: Mapped[str] = mapped_column(String(200), default="")
    created_at: Mapped[datetime] = mapped_column(DateTime(timezone=True), default=now)
    expires_at: Mapped[datetime | None] = mapped_column(DateTime(timezone=True))
    revoked_at: Mapped[datetime | None] = mapped_column(DateTime(timezone=True))


class TeamFile(Base):
    """One uploaded version of a team's file (``team_config`` or ``credentials``)."""

    __tablename__ = "team_files"
    __table_args__ = (UniqueConstraint("team_id", "kind", "version"),)

    id: Mapped[int] = mapped_column(Integer, primary_key=True)
    team_id: Mapped[int] = mapped_column(ForeignKey("teams.id"), index=True)
    kind: Mapped[str] = mapped_column(String(32))
    version: Mapped[int] = mapped_column(Integer)
    content: Mapped[str] = mapped_column(Text)
    sha256: Mapped[str] = mapped_column(String(64))
    valid: Mapped[bool] = mapped_column(Boolean)
    problems_json: Mapped[str] = mapped_column(Text, default="[]")
    created_at: Mapped[datetime] = mapped_column(DateTime(timezone=True), default=now)


class Submission(Base):
    __tablename__ = "submissions"
    __table_args__ = (
        # One queued, starting or running test match per team, kept by the database itself.
        Index("one_active_submission_per_team", "team_id", unique=True,
              sqlite_where=text(_ACTIVE_SQL), postgresql_where=text(_ACTIVE_SQL)),
        Index("submissions_by_state", "state", "seq"),
    )

    seq: Mapped[int] = mapped_column(Integer, primary_key=True)
    id: Mapped[str] = mapped_column(String(32), unique=True)
    team_id: Mapped[int] = mapped_column(ForeignKey("teams.id"), index=True)
    opponent: Mapped[str] = mapped_column(String(64))
    team_file_id: Mapped[int] = mapped_column(ForeignKey("team_files.id"))
    credentials_file_id: Mapped[int | None] = mapped_column(ForeignKey("team_files.id"))
    state: Mapped[str] = mapped_column(String(16), default=SubmissionState.QUEUED.value)
    created_at: Mapped[datetime] = mapped_column(DateTime(timezone=True), default=now)
    started_at: Mapped[datetime | None] = mapped_column(DateTime(timezone=True))
    finished_at: Mapped[datetime | None] = mapped_column(DateTime(timezone=True))
    attempts: Mapped[int] = mapped_column(Integer, default=0)
    match_id: Mapped[str | None] = mapped_column(String(64))
    pool_handle: Mapped[str | None] = mapped_column(String(200))
    cancel_requested: Mapped[bool] = mapped_column(Boolean, default=False)
    charged: Mapped[bool] = mapped_column(Boolean, default=False)
    failure_class: Mapped[str | None] = mapped_column(String(32))
    failure_side: Mapped[str | None] = mapped_column(String(16))
    cause: Mapped[str | None] = mapped_column(Text)
    preflight_s: Mapped[float | None] = mapped_column(Float)
    video_state: Mapped[str | None] = mapped_column(String(16))  # see MediaState
    video_detail: Mapped[str | None] = mapped_column(Text)
    delivery_state: Mapped[str | None] = mapped_column(String(16))  # see MediaState
    delivery_detail: Mapped[str | None] = mapped_column(Text)
    pool_detail: Mapped[str | None] = mapped_column(Text)  # why a cluster keeps it waiting


class Notification(Base):
    """Outbox of mails and webhooks: written with the state change, sent by the worker."""

    __tablename__ = "notifications"

    id: Mapped[int] = mapped_column(Integer, primary_key=True)
    delivery_id: Mapped[str] = mapped_column(String(40), unique=True)
    team_id: Mapped[int] = mapped_column(ForeignKey("teams.id"), index=True)
    submission_id: Mapped[str] = mapped_column(String(32))
    channel: Mapped[str] = mapped_column(String(16))  # mail | webhook
    event: Mapped[str] = mapped_column(String(32))  # submission.started | .finished | .failed
    payload_json: Mapped[str] = mapped_column(Text)
    attempts: Mapped[int] = mapped_column(Integer, default=0)
    next_attempt_at: Mapped[datetime] = mapped_column(DateTime(timezone=True), default=now)
    sent_at: Mapped[datetime | None] = mapped_column(DateTime(timezone=True))
    given_up: Mapped[bool] = mapped_column(Boolean, default=False)
    last_error: Mapped[str | None] = mapped_column(Text)


class ServiceFlag(Base):
    """Small key/value state of the service (``queue_paused``)."""

    __tablename__ = "service_flags"

    key: Mapped[str] = mapped_column(String(64), primary_key=True)
    value: Mapped[str] = mapped_column(String(200))
    updated_at: Mapped[datetime] = mapped_column(DateTime(timezone=True), default=now)


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
    "now",
    "utc",
]
