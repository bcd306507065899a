"""The status of every active submission, rendered together by a background thread.

Status polls are the service's hottest path (a dashboard per team, every second). A poll whose
token is in the token cache and whose submission is on the board is answered from memory by
:class:`service.middleware.StatusFastPath`, before routing: no database query, no worker
thread, no serialization. The board is rebuilt by one query every ``ttl_s`` seconds, by its own
thread and only while polls read it, so a poll never waits for a rebuild (it reads the previous
board meanwhile). A submission this process creates is put on the board at once; one it
changes otherwise (cancel) is dropped from it at once (its next poll reads the database), also
from a rebuild that was under way; queue
controls and worker rounds that changed something set the whole board aside until the early
rebuild they ask for is done. Other submissions' positions may lag a change by about
``ttl_s``. Each rebuild also runs the ``also`` callbacks with its session (the token cache
checks its tokens again there, see :meth:`service.tokens.TokenCache.revalidate`). A board older
than ``max_age_s`` (its thread stalled) is not used. A team only ever gets its own
submissions from the board.
"""

from __future__ import annotations

import logging
import threading
import time
from collections.abc import Callable, Sequence

from sqlalchemy import select
from sqlalchemy.orm import Session, sessionmaker

from service.db import ACTIVE_STATES, Submission, Team

log = logging.getLogger(__name__)

Render = Callable[[Session, Submission, str], bytes]
"""(session, row, team name) -> the JSON body of the row's status."""

MIN_GAP_S = 0.2
"""Rebuilds asked for early are at least this far apart."""

IDLE_S = 30.0
"""No rebuild when no poll has read the board for this long."""


class StatusBoard:
    def __init__(self, *, render: Render, ttl_s: float = 2.0, max_age_s: float | None = None,
                 also: Sequence[Callable[[Session], None]] = ()) -> None:
        self.render = render
        self.also = tuple(also)
        self.ttl_s = ttl_s
        self.max_age_s = max_age_s if max_age_s is not None else max(10 * ttl_s, 5.0)
        self._bodies: dict[str, tuple[int, bytes]] = {}
        self._at = float("-inf")  # monotonic time of the query the board was built from
        self._read_at = float("-inf")
        self._invalidated_at = float("-inf")
        # submissions this process changed: when, and their new entry (None: dropped)
        self._changed: dict[str, tuple[float, tuple[int, bytes] | None]] = {}
        self._lock = threading.Lock()
        self._wake = threading.Event()
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None

    # the refresher thread ------------------------------------------------------------------
    def start(self, sessions: sessionmaker[Session]) -> None:
        self._stop.clear()
        self._thread = threading.Thread(target=self._run, args=(sessions,),
                                        name="status-board", daemon=True)
        self._thread.start()

    def stop(self) -> None:
        self._stop.set()
        self._wake.set()
        if self._thread is not None:
            self._thread.join(timeout=10)

    def _run(self, sessions: sessionmaker[Session]) -> None:
        while not self._stop.is_set():
            if time.monotonic() - self._read_at < IDLE_S:
                try:
                    with sessions() as session:
                        self.refresh(session)
                        session.commit()
                except Exception:  # the thread's boundary: polls fall back to the database
                    log.exception("status board rebuild failed; retrying")
            began = time.monotonic()
            self._wake.wait(self.ttl_s)
            self._wake.clear()
            # woken early (a change, a poll the board missed): not more often than this
            self._stop.wait(max(0.0, min(MIN_GAP_S, self.ttl_s) - (time.monotonic() - began)))

    # changes -------------------------------------------------------------------------------
    def invalidate(self) -> None:
        """Something changed for many submissions (queue paused, a match started): the board
        is not used until it has been rebuilt, which happens at once."""
        self._invalidated_at = time.monotonic()
        self._wake.set()

    def missed(self) -> None:
        """A poll missed the board (its submission is not on it, or its token not in the
        cache, e.g. after a quiet spell): rebuild soon, so that the next polls find them."""
        self._read_at = time.monotonic()
        self._wake.set()

    def forget(self, submission_id: str) -> None:
        """Drop one submission (it changed); the others stay until the next rebuild."""
        with self._lock:
            self._bodies.pop(submission_id, None)
            self._changed[submission_id] = (time.monotonic(), None)

    def put(self, submission_id: str, team_id: int, body: bytes) -> None:
        """The status of a submission this process just made: on the board at once."""
        with self._lock:
            self._bodies[submission_id] = (team_id, body)
            self._changed[submission_id] = (time.monotonic(), (team_id, body))

    # reads ---------------------------------------------------------------------------------
    def lookup(self, submission_id: str, team_id: int | None) -> bytes | None:
        """The body when the board is recent and holds this team's submission, else None."""
        current = time.monotonic()
        self._read_at = current
        built = self._at
        if current - built >= self.max_age_s or built < self._invalidated_at:
            return None
        found = self._bodies.get(submission_id)  # a dict read is atomic; the dict is replaced
        if found is None or found[0] != team_id:
            return None
        return found[1]

    def refresh(self, session: Session) -> None:
        """Rebuild the board from one query (the thread does this every ``ttl_s``)."""
        started = time.monotonic()
        for callback in self.also:
            callback(session)
        rows = session.execute(select(Submission, Team.name).join(
            Team, Team.id == Submission.team_id).where(
            Submission.state.in_([s.value for s in ACTIVE_STATES]))).all()
        bodies = {row.id: (row.team_id, self.render(session, row, name)) for row, name in rows}
        with self._lock:
            for sid, (when, entry) in list(self._changed.items()):
                if when < started:
                    del self._changed[sid]  # the query saw the change
                elif entry is None:  # changed while this board was being built
                    bodies.pop(sid, None)
                else:
                    bodies[sid] = entry
            self._bodies = bodies
            self._at = started


__all__ = ["Render", "StatusBoard"]
