"""Tables of the ladder (:mod:`service.ratings`, :mod:`service.ladder`); the schema is owned by
Alembic (``0006_ladder``)."""

from __future__ import annotations

from datetime import datetime

from sqlalchemy import Boolean, DateTime, Integer, String, Text, UniqueConstraint
from sqlalchemy.orm import Mapped, mapped_column

from service.db.models import Base, now


class RatedMatch(Base):
    """A finished match considered once for the ratings: a friendly between two teams (``source``
    ``friendly``, ``ref`` the submission id) or an official match of the tournament
    (``official``, the schedule's match id). ``counted`` is false for a match that did not play
    (``note`` says why); it stays here so that it is never considered again."""

    __tablename__ = "rated_matches"
    __table_args__ = (UniqueConstraint("source", "ref"),)

    id: Mapped[int] = mapped_column(Integer, primary_key=True)
    source: Mapped[str] = mapped_column(String(16))
    ref: Mapped[str] = mapped_column(String(64))
    red_team: Mapped[str] = mapped_column(String(64))
    blue_team: Mapped[str] = mapped_column(String(64))
    red_goals: Mapped[int | None] = mapped_column(Integer)
    blue_goals: Mapped[int | None] = mapped_column(Integer)
    winner: Mapped[str | None] = mapped_column(String(8))  # red | blue | draw
    counted: Mapped[bool] = mapped_column(Boolean)
    note: Mapped[str | None] = mapped_column(Text)
    played_at: Mapped[datetime] = mapped_column(DateTime(timezone=True))
    recorded_at: Mapped[datetime] = mapped_column(DateTime(timezone=True), default=now)


class LadderFixture(Base):
    """A friendly the ladder scheduled (its submission is not charged to the team)."""

    __tablename__ = "ladder_fixtures"

    submission_id: Mapped[str] = mapped_column(String(32), primary_key=True)
    red_team: Mapped[str] = mapped_column(String(64))
    blue_team: Mapped[str] = mapped_column(String(64))
    created_at: Mapped[datetime] = mapped_column(DateTime(timezone=True), default=now)


__all__ = ["LadderFixture", "RatedMatch"]
