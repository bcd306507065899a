"""Tables of the results of finished matches (:mod:`service.results`); the schema is owned by
Alembic (``0007_match_results``).

One :class:`MatchResultRow` per submission whose match left a ``results.json``, written once by
the queue worker as it ends the submission, and one :class:`MatchTeamRow` per colour. The match
folder may be removed afterwards: the API, the pages, the ladder and the mail read these rows.
"""

from __future__ import annotations

from datetime import datetime

from sqlalchemy import DateTime, Float, ForeignKey, Integer, String
from sqlalchemy.orm import Mapped, mapped_column, relationship

from service.db.models import Base, now


class MatchResultRow(Base):
    """The score and the play summary of one finished match (``results.json``)."""

    __tablename__ = "match_results"

    submission_id: Mapped[str] = mapped_column(ForeignKey("submissions.id"), primary_key=True)
    match_id: Mapped[str] = mapped_column(String(64))
    status: Mapped[str] = mapped_column(String(16))  # success | failed
    failure_class: Mapped[str | None] = mapped_column(String(32))
    failure_team: Mapped[str | None] = mapped_column(String(8))  # red | blue: who caused it
    final_state: Mapped[str | None] = mapped_column(String(32))
    winner: Mapped[str | None] = mapped_column(String(8))  # red | blue | draw
    red_goals: Mapped[int | None] = mapped_column(Integer)
    blue_goals: Mapped[int | None] = mapped_column(Integer)
    red_shootout: Mapped[int | None] = mapped_column(Integer)  # only after a shoot-out
    blue_shootout: Mapped[int | None] = mapped_column(Integer)
    halves_playing: Mapped[str | None] = mapped_column(String(32))  # "1,2"; NULL: no play
    playing_s: Mapped[float | None] = mapped_column(Float)
    sim_time_ms: Mapped[int | None] = mapped_column(Integer)
    real_time_factor: Mapped[float | None] = mapped_column(Float)
    recorded_at: Mapped[datetime] = mapped_column(DateTime(timezone=True), default=now)
    teams: Mapped[list[MatchTeamRow]] = relationship(
        order_by="MatchTeamRow.color.desc()", cascade="all, delete-orphan", lazy="selectin")


class MatchTeamRow(Base):
    """One side's figures in a finished match: its goals, what the referee counted of its play
    (NULL when no football was played) and how its robots ended."""

    __tablename__ = "match_team_results"

    submission_id: Mapped[str] = mapped_column(ForeignKey("match_results.submission_id"),
                                               primary_key=True)
    color: Mapped[str] = mapped_column(String(8), primary_key=True)  # red | blue
    team: Mapped[str] = mapped_column(String(64))
    goals: Mapped[int | None] = mapped_column(Integer)
    kicks: Mapped[int | None] = mapped_column(Integer)
    shots: Mapped[int | None] = mapped_column(Integer)
    own_goals: Mapped[int | None] = mapped_column(Integer)
    falls: Mapped[int | None] = mapped_column(Integer)
    robots: Mapped[int] = mapped_column(Integer)
    robots_exited: Mapped[int] = mapped_column(Integer)  # exited during the game
    robots_oom_killed: Mapped[int] = mapped_column(Integer)


__all__ = ["MatchResultRow", "MatchTeamRow"]
