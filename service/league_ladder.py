"""The ladder: friendlies scheduled automatically between teams that accept them.

Every ``ladder_interval_s`` seconds (:class:`service.settings.Settings`, 0: no ladder, the
default), when the queue has nothing waiting and a match slot is free, the ladder queues one
friendly: the team that has waited longest since its last ladder friendly plays the team of the
nearest rating (:mod:`service.league`) among the others that accept friendlies, each with its
latest team file that passed its checks. Teams with an active match of their own are left
alone. The friendly is an ordinary submission of the first team against the second (so it
shows, is watched and rated like one); its images are checked when the match pulls them.
"""

from __future__ import annotations

import logging
import threading
import time
from typing import TYPE_CHECKING

from sqlalchemy import select
from sqlalchemy.orm import Session

from service import league, submissions, teamfiles
from service.db import ACTIVE_STATES, Submission, SubmissionState, Team, transaction
from service.errors import NotFound

if TYPE_CHECKING:
    from service.app import Services

log = logging.getLogger(__name__)


def eligible(session: Session) -> list[Team]:
    """Teams that accept friendlies, have a valid team file and no active match."""
    active = set(session.scalars(select(Submission.team_id).where(
        Submission.state.in_([s.value for s in ACTIVE_STATES]))))
    teams = []
    for team in session.scalars(select(Team).where(Team.accepts_friendlies.is_(True))
                                .order_by(Team.name)):
        if team.id in active:
            continue
        try:
            teamfiles.get(session, team_id=team.id, kind="team_config")
        except NotFound:
            continue
        teams.append(team)
    return teams


def pick(session: Session, results_dir: object) -> tuple[Team, Team] | None:
    """The next pairing: the longest-waiting eligible team and the eligible team nearest to it
    in rating; None with fewer than two eligible teams."""
    teams = eligible(session)
    if len(teams) < 2:
        return None
    standings = {s.team: s for s in league.league(session, results_dir)}
    last_played: dict[int, int] = {}
    for row in session.scalars(select(Submission).where(Submission.opponent != league.STUB)
                               .order_by(Submission.seq)):
        last_played[row.team_id] = row.seq
        opponent = next((t for t in teams if t.name == row.opponent), None)
        if opponent is not None:
            last_played[opponent.id] = row.seq
    first = min(teams, key=lambda t: (last_played.get(t.id, -1), t.name))

    def rating(team: Team) -> float:
        entry = standings.get(team.name)
        return entry.rating if entry is not None else 0.0

    others = [t for t in teams if t.id != first.id]
    second = min(others, key=lambda t: (abs(rating(t) - rating(first)),
                                        last_played.get(t.id, -1), t.name))
    return first, second


def schedule_one(services: Services) -> str | None:
    """Queue one ladder friendly when the queue is idle and a slot is free; its id or None."""
    with transaction(services.sessions) as session:
        if submissions.queue_paused(session):
            return None
        queued = session.scalar(select(Submission.id).where(
            Submission.state == SubmissionState.QUEUED.value).limit(1))
        running = len(list(session.scalars(select(Submission.id).where(Submission.state.in_(
            [SubmissionState.STARTING.value, SubmissionState.RUNNING.value])))))
        if queued is not None or running >= services.slots():
            return None
        pair = pick(session, services.pool.results_dir)
        if pair is None:
            return None
        first, second = pair
        team_file = teamfiles.get(session, team_id=first.id, kind="team_config")
        row = submissions.create(
            session, team_id=first.id, opponent=second.name, team_file_id=team_file.id,
            credentials_file_id=teamfiles.newest_id(session, team_id=first.id,
                                                    kind="credentials"),
            preflight_s=None)
        log.info("ladder: friendly %s, %s against %s", row.id, first.name, second.name)
        ident = row.id
    services.changed(ident)
    if services.worker is not None:
        services.worker.wake()
    return ident


class Ladder:
    """The thread that schedules ladder friendlies at the operator's rate."""

    def __init__(self, services: Services) -> None:
        self.services = services
        self.interval_s = services.settings.ladder_interval_s
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None

    def start(self) -> None:
        self._thread = threading.Thread(target=self._run, name="ladder", daemon=True)
        self._thread.start()

    def stop(self) -> None:
        self._stop.set()
        if self._thread is not None:
            self._thread.join(timeout=30)

    def _run(self) -> None:
        next_at = time.monotonic()
        while not self._stop.is_set():
            if time.monotonic() >= next_at:
                try:
                    if schedule_one(self.services) is not None:
                        next_at = time.monotonic() + self.interval_s
                except Exception:  # the thread's boundary: log, try again next time
                    log.exception("ladder round failed; retrying")
                    next_at = time.monotonic() + self.interval_s
            self._stop.wait(min(1.0, self.interval_s))


__all__ = ["Ladder", "eligible", "pick", "schedule_one"]
