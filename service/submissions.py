"""Test-match submissions: create, cancel, queue position and expected start. Domain code.

States (see :class:`service.db.SubmissionState`): a submission is QUEUED when accepted; the
worker moves it to STARTING, asks the pool, then RUNNING; it ends DONE, FAILED or CANCELLED.
A team has at most one active (queued, starting or running) submission; the database's
partial unique index keeps that true even for simultaneous requests.
"""

from __future__ import annotations

import asyncio
import heapq
import logging
import secrets
import threading
import time
from collections.abc import AsyncIterator
from contextlib import asynccontextmanager
from dataclasses import dataclass
from datetime import datetime, timedelta

from sqlalchemy import select
from sqlalchemy.exc import IntegrityError
from sqlalchemy.orm import Session

from service.db import (
    ACTIVE_STATES,
    ServiceFlag,
    Submission,
    SubmissionState,
    Team,
    now,
    utc,
)
from service.errors import Conflict, InvalidInput, NotFound

log = logging.getLogger(__name__)

STUB = "stub"
TEAM_SIDE = {"image_pull", "team_startup", "team_crash"}
LEAGUE_SIDE = {"infrastructure", "simulator", "referee", "not_played"}
ABSENT = "team_absent"
"""No robot of one team connected, so nothing was played: that team's side (``team`` of the
report), never the other's."""


def failure_side(failure_class: str | None, team: str | None = None,
                 own_color: str = "red") -> str | None:
    """Whose side a failure was on: ``team``, ``league`` or None (no failure / cancelled).
    ``team`` is the colour the match report blames (the submitting team plays ``own_color``);
    an absent opponent (the stub, or a friendly's) is not the submitting team's doing."""
    if failure_class == ABSENT:
        return "team" if team == own_color else "league"
    if failure_class in TEAM_SIDE:
        return "team"
    if failure_class in LEAGUE_SIDE:
        return "league"
    return None


def active_of(session: Session, team_id: int) -> Submission | None:
    states = [s.value for s in ACTIVE_STATES]
    return session.scalar(select(Submission).where(
        Submission.team_id == team_id, Submission.state.in_(states)))


def check_opponent(session: Session, *, team_id: int, opponent: str) -> None:
    if opponent == STUB:
        return
    other = session.scalar(select(Team).where(Team.name == opponent))
    if other is None or other.id == team_id or not other.accepts_friendlies:
        names = [STUB, *session.scalars(select(Team.name).where(
            Team.accepts_friendlies.is_(True), Team.id != team_id))]
        raise InvalidInput(
            f"opponent {opponent!r} is not a team that accepts friendlies "
            f"(expected one of: {', '.join(names)})",
            problems=[{"pointer": "/opponent", "message": "unknown opponent",
                       "expected": " | ".join(names)}])


def refuse_if_active(session: Session, team_id: int) -> None:
    existing = active_of(session, team_id)
    if existing is not None:
        raise Conflict(f"the team already has an active test match {existing.id} "
                       f"({existing.state}); cancel it or wait until it ends",
                       existing_id=existing.id)


def create(session: Session, *, team_id: int, opponent: str, team_file_id: int,
           credentials_file_id: int | None, preflight_s: float | None) -> Submission:
    """Insert a QUEUED submission; 409 when the team already has an active one."""
    row = Submission(id="sub_" + secrets.token_hex(6), team_id=team_id, opponent=opponent,
                     team_file_id=team_file_id, credentials_file_id=credentials_file_id,
                     state=SubmissionState.QUEUED.value, preflight_s=preflight_s, attempts=0,
                     cancel_requested=False, charged=False)
    try:
        with session.begin_nested():
            session.add(row)
            session.flush()
    except IntegrityError:
        refuse_if_active(session, team_id)
        raise
    log.info("submission %s queued (team %d, opponent %s)", row.id, team_id, opponent)
    return row


def get_own(session: Session, *, team_id: int, submission_id: str,
            for_update: bool = False) -> Submission:
    """The team's submission; another team's id is 'not found', like an unknown one."""
    query = select(Submission).where(Submission.id == submission_id)
    row = session.scalar(query.with_for_update() if for_update else query)
    if row is None or row.team_id != team_id:
        raise NotFound(what="submission", ident=submission_id)
    return row


def cancel(session: Session, row: Submission) -> Submission:
    """Queued: cancelled at once, not charged. Running: the worker stops it gracefully."""
    state = SubmissionState(row.state)
    if state is SubmissionState.QUEUED:
        row.state = SubmissionState.CANCELLED.value
        row.finished_at = now()
        row.cause = "cancelled by the team while queued"
        row.charged = False
        log.info("submission %s cancelled while queued", row.id)
    elif state in (SubmissionState.STARTING, SubmissionState.RUNNING):
        row.cancel_requested = True
        log.info("submission %s: cancel requested while %s", row.id, state.value)
    else:
        raise Conflict(f"submission {row.id} has already ended ({row.state})",
                       existing_id=row.id)
    return row


class PreflightClaims:
    """At most one pre-flight check per team at a time: a team's second submission while its
    first is being checked waits for it (in the event loop: no request thread is held) and is
    then answered as any later one (409 naming the submission that got in first)."""

    def __init__(self) -> None:
        self._locks: dict[int, asyncio.Lock] = {}

    @asynccontextmanager
    async def claim(self, team_id: int) -> AsyncIterator[None]:
        lock = self._locks.setdefault(team_id, asyncio.Lock())
        async with lock:
            yield


def queue_paused(session: Session) -> bool:
    flag = session.get(ServiceFlag, "queue_paused")
    return flag is not None and flag.value == "1"


def set_queue_paused(session: Session, paused: bool) -> None:
    flag = session.get(ServiceFlag, "queue_paused")
    if flag is None:
        session.add(ServiceFlag(key="queue_paused", value="1" if paused else "0"))
    else:
        flag.value = "1" if paused else "0"
        flag.updated_at = now()
    log.info("queue %s", "paused" if paused else "resumed")


@dataclass(frozen=True, slots=True)
class QueueInfo:
    position: int | None  # 1 = next to start
    expected_start: datetime | None
    reason: str | None


class MatchTimes:
    """The average wall time of recent test matches, recomputed at most every ``ttl_s``."""

    def __init__(self, *, default_s: float, ttl_s: float = 10.0) -> None:
        self.default_s = default_s
        self.ttl_s = ttl_s
        self._value = default_s
        self._at = -ttl_s
        self._lock = threading.Lock()

    def average_s(self, session: Session) -> float:
        with self._lock:
            if time.monotonic() - self._at < self.ttl_s:
                return self._value
        rows = session.execute(select(Submission.started_at, Submission.finished_at).where(
            Submission.state == SubmissionState.DONE.value, Submission.started_at.is_not(None),
            Submission.finished_at.is_not(None)).order_by(Submission.seq.desc()).limit(20)).all()
        durations = [(utc(end) - utc(start)).total_seconds() for start, end in rows
                     if start and end]
        with self._lock:
            self._value = sum(durations) / len(durations) if durations else self.default_s
            self._at = time.monotonic()
            return self._value


class QueueBoard:
    """Position, expected start and reason of every queued submission, computed together and
    kept for ``ttl_s`` seconds: status polls read it (one lookup instead of four queries);
    changes made in this process call :meth:`invalidate`."""

    def __init__(self, *, times: MatchTimes, ttl_s: float = 0.5) -> None:
        self.times = times
        self.ttl_s = ttl_s
        self._board: dict[int, QueueInfo] = {}
        self._at = -ttl_s
        self._lock = threading.Lock()

    def invalidate(self) -> None:
        with self._lock:
            self._at = -self.ttl_s

    def info(self, session: Session, row: Submission, *, slots: int) -> QueueInfo:
        if row.state != SubmissionState.QUEUED.value:
            return QueueInfo(None, None, None)
        with self._lock:
            fresh = time.monotonic() - self._at < self.ttl_s
            found = self._board.get(row.seq) if fresh else None
        if found is None:
            board = self._compute(session, slots)
            with self._lock:
                self._board, self._at = board, time.monotonic()
            found = board.get(row.seq, QueueInfo(None, None, None))
        return found

    def _compute(self, session: Session, slots: int) -> dict[int, QueueInfo]:
        queued = list(session.scalars(select(Submission.seq).where(
            Submission.state == SubmissionState.QUEUED.value).order_by(Submission.seq)))
        paused = session.scalar(select(ServiceFlag.value).where(
            ServiceFlag.key == "queue_paused")) == "1"
        if paused:
            reason = "the queue is paused by the league's operators"
            return {seq: QueueInfo(n + 1, None, reason) for n, seq in enumerate(queued)}
        running = list(session.scalars(select(Submission.started_at).where(Submission.state.in_(
            [SubmissionState.STARTING.value, SubmissionState.RUNNING.value]))))
        duration = timedelta(seconds=self.times.average_s(session))
        current = now()
        free = [max(current, utc(start) + duration) if start else current + duration
                for start in running[:slots]]
        free += [current] * max(0, slots - len(free))
        heapq.heapify(free)
        busy = min(len(running), slots)
        board = {}
        for ahead, seq in enumerate(queued):
            start = heapq.heappop(free)
            heapq.heappush(free, start + duration)
            if ahead:
                reason = (f"{ahead} submission(s) ahead in the queue; {busy} of {slots} match "
                          "slot(s) busy")
            elif busy >= slots:
                reason = f"next in line; all {slots} match slot(s) busy"
            else:
                reason = "next in line; starting shortly"
            board[seq] = QueueInfo(ahead + 1, start, reason)
        return board


__all__ = [
    "MatchTimes",
    "QueueBoard",
    "QueueInfo",
    "STUB",
    "active_of",
    "cancel",
    "check_opponent",
    "create",
    "failure_side",
    "get_own",
    "queue_paused",
    "refuse_if_active",
    "set_queue_paused",
]
