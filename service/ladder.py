"""The ladder: a thread of the service that rates finished matches and schedules friendlies.

Each round it (1) records the friendlies and, with ``HLVS_SERVICE_SCHEDULE_STATE``, the official
matches that ended since the last round (:mod:`service.ratings`; each once), and (2) when
``HLVS_SERVICE_LADDER_EVERY_S`` is above 0, at most that often, schedules one friendly in a free
slot: only while the queue is not paused, nothing is queued and the pool has a slot free, so
the teams' own test matches never wait for the ladder.

The pairing: among the teams that accept friendlies, have a team file and no active test match,
the team that waited longest since its last ladder match plays, against the team of the
closest rating (then the one it met least often on the ladder, then by name). It plays with its
current team file (:func:`service.teamfiles.current`: the newest whose pre-flight passed), as
the submitting (red) team; the opponent's current file is used as for any friendly. The
submission is a normal test match of the team, marked as a ladder fixture
(:class:`service.db.ladder.LadderFixture`): it is not charged to the team.

Restart safety: the time of the last fixture is read from the database, and a match is recorded
once (unique by its id), so a restart neither schedules early nor counts twice.
"""

from __future__ import annotations

import logging
import threading
import time
from collections import Counter
from collections.abc import Callable
from datetime import timedelta
from pathlib import Path
from typing import TYPE_CHECKING

from sqlalchemy import func, select
from sqlalchemy.orm import Session

from service import ratings, submissions, teamfiles
from service.db import ACTIVE_STATES, Submission, SubmissionState, Team, TeamFile, now, transaction
from service.db import utc as as_utc
from service.db.ladder import LadderFixture
from service.matchfiles import OWN_COLOR
from service.ratings import LadderCache

if TYPE_CHECKING:
    from sqlalchemy.orm import sessionmaker

    from service.services import Background
    from service.settings import Settings

log = logging.getLogger(__name__)

OFFICIAL_EVERY_S = 5.0
"""The tournament's ledger is read for newly played official matches at most this often."""


def is_fixture(session: Session, submission_id: str) -> bool:
    """Whether the submission is a friendly the ladder scheduled (not charged to the team)."""
    return session.get(LadderFixture, submission_id) is not None


def watchable(session: Session, *, team_id: int, team_name: str | None,
              submission_id: str) -> Submission:
    """The team's own submission, or a friendly it was the opponent in (its replay is the
    team's too); anything else is 'not found', like an unknown id."""
    row = session.scalar(select(Submission).where(Submission.id == submission_id))
    if row is not None and (row.team_id == team_id or (
            team_name is not None and row.opponent == team_name)):
        return row
    return submissions.get_own(session, team_id=team_id, submission_id=submission_id)


def logs_side(session: Session, *, team_id: int, team_name: str | None,
              submission_id: str) -> tuple[Submission, str]:
    """The submission and the colour whose robots' logs the team may read: its own (red), or
    blue in a friendly the ladder scheduled against it (never the other side's); anything else
    is 'not found', like an unknown id."""
    row = session.scalar(select(Submission).where(Submission.id == submission_id))
    if row is not None and row.team_id != team_id and team_name is not None:
        fixture = session.get(LadderFixture, submission_id)
        if fixture is not None and fixture.blue_team == team_name:
            return row, "blue"
    return submissions.get_own(session, team_id=team_id, submission_id=submission_id), OWN_COLOR


class LadderThread:
    def __init__(
        self, *, settings: Settings, sessions: sessionmaker[Session], cache: LadderCache,
        changed: Callable[[], None], slots: Callable[[], int],
        worker: Background | None = None,
    ) -> None:
        """``changed``: told when a friendly was queued; ``slots``: the matches that may
        play at once; ``worker``: woken when a friendly was queued."""
        self.settings = settings
        self._sessions = sessions
        self.cache = cache
        self._changed = changed
        self._slots = slots
        self._worker = worker
        self._stop = threading.Event()
        self._wake = threading.Event()
        self._thread: threading.Thread | None = None
        self._ledger_read = -OFFICIAL_EVERY_S

    def start(self) -> None:
        self._thread = threading.Thread(target=self._run, name="ladder", daemon=True)
        self._thread.start()

    def wake(self) -> None:
        """Run a round now rather than at the next poll."""
        self._wake.set()

    def stop(self) -> None:
        self._stop.set()
        self._wake.set()
        if self._thread is not None:
            self._thread.join(timeout=30)

    def _run(self) -> None:
        while not self._stop.is_set():
            try:
                self.round()
            except Exception:  # the thread's boundary: log, keep serving
                log.exception("ladder round failed; retrying")
            self._wake.wait(max(self.settings.worker_poll_s, 0.05))
            self._wake.clear()

    # one round ---------------------------------------------------------------------------
    def round(self) -> str | None:
        """Record finished matches, then perhaps schedule one; the new submission's id."""
        with transaction(self._sessions) as session:
            recorded = ratings.record_friendlies(session)
            state = self.settings.schedule_state
            if state and Path(state).is_file() and \
                    time.monotonic() - self._ledger_read >= OFFICIAL_EVERY_S:
                self._ledger_read = time.monotonic()
                recorded += ratings.record_official(session, Path(state))
        if recorded:
            log.info("ladder: %d finished match(es) recorded", recorded)
        if self.settings.ladder_every_s <= 0:
            return None
        with transaction(self._sessions) as session:
            sid = self._schedule(session)
        if sid is not None:
            self._changed()
            worker = self._worker
            if worker is not None:
                worker.wake()
        return sid

    def _schedule(self, session: Session) -> str | None:
        last = session.scalar(select(func.max(LadderFixture.created_at)))
        if last is not None and now() - as_utc(last) < timedelta(
                seconds=self.settings.ladder_every_s):
            return None
        if submissions.queue_paused(session) or session.scalar(
                select(Submission.seq).where(
                    Submission.state == SubmissionState.QUEUED.value).limit(1)) is not None:
            return None
        busy = session.scalar(select(func.count()).select_from(Submission).where(
            Submission.state.in_([SubmissionState.STARTING.value,
                                  SubmissionState.RUNNING.value]))) or 0
        if busy >= self._slots():
            return None
        pair = self._pair(session)
        if pair is None:
            return None
        team, opponent, team_file = pair
        row = submissions.create(session, team_id=team.id, opponent=opponent.name,
                                 team_file_id=team_file, credentials_file_id=_newest(
                                     session, team.id, "credentials"), preflight_s=None)
        session.add(LadderFixture(submission_id=row.id, red_team=team.name,
                                  blue_team=opponent.name))
        session.flush()
        log.info("ladder: %s against %s scheduled as %s", team.name, opponent.name, row.id)
        return row.id

    def _pair(self, session: Session) -> tuple[Team, Team, int] | None:
        active = set(session.scalars(select(Submission.team_id).where(
            Submission.state.in_([s.value for s in ACTIVE_STATES]))))
        files: dict[int, int] = {}
        teams: list[Team] = []
        for team in session.scalars(select(Team).where(Team.accepts_friendlies.is_(True))
                                    .order_by(Team.name)):
            current = teamfiles.current(session, team_id=team.id)
            if current is not None and team.id not in active:
                files[team.id] = current.id
                teams.append(team)
        if len(teams) < 2:
            return None
        fixtures = list(session.scalars(select(LadderFixture).order_by(
            LadderFixture.created_at)))
        last_played = {}
        met: Counter[frozenset[str]] = Counter()
        for fixture in fixtures:
            last_played[fixture.red_team] = last_played[fixture.blue_team] = fixture.created_at
            met[frozenset((fixture.red_team, fixture.blue_team))] += 1
        order = {name: n for n, name in enumerate(
            sorted(t.name for t in teams if t.name not in last_played))}
        team = min(teams, key=lambda t: (t.name in last_played,
                                         as_utc(last_played[t.name]).timestamp()
                                         if t.name in last_played else order[t.name]))
        table = self.cache.get(session).teams
        mine = table[team.name].rating if team.name in table else 0.0
        opponent = min((t for t in teams if t.id != team.id), key=lambda t: (
            abs((table[t.name].rating if t.name in table else 0.0) - mine),
            met[frozenset((team.name, t.name))], t.name))
        return team, opponent, files[team.id]


def _newest(session: Session, team_id: int, kind: str) -> int | None:
    """The team's latest valid file of ``kind``."""
    return session.scalar(select(TeamFile.id).where(
        TeamFile.team_id == team_id, TeamFile.kind == kind, TeamFile.valid.is_(True))
        .order_by(TeamFile.version.desc()).limit(1))


__all__ = ["LadderThread", "is_fixture", "logs_side", "watchable"]
