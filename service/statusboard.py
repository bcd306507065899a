"""The status of every active submission, rendered together and kept for ``ttl_s`` seconds.

Status polls are the service's hottest path (a dashboard per team, every second). With the
board fresh and the caller's token in the token cache, ``GET /v1/submissions/{id}`` answers
from memory without a database query or a worker thread; the board is rebuilt by one query
when it is stale. A submission this process changes (submit, cancel) is dropped from it at
once; queue controls and worker rounds that changed something invalidate it whole. Other
submissions' positions may lag a change by up to ``ttl_s``. A team only ever gets its own
submissions from the board.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable

from sqlalchemy import select
from sqlalchemy.orm import Session

from service.db import ACTIVE_STATES, Submission, Team

Render = Callable[[Session, Submission, str], bytes]
"""(session, row, team name) -> the JSON body of the row's status."""


class StatusBoard:
    def __init__(self, *, render: Render, ttl_s: float = 0.5) -> None:
        self.render = render
        self.ttl_s = ttl_s
        self._bodies: dict[str, tuple[int, bytes]] = {}
        self._at = -ttl_s
        self._lock = threading.Lock()
        self._refreshing = threading.Lock()

    def invalidate(self) -> None:
        with self._lock:
            self._at = -self.ttl_s

    def forget(self, submission_id: str) -> None:
        """Drop one submission (it changed); the others stay until the board is stale."""
        with self._lock:
            self._bodies.pop(submission_id, None)

    def lookup(self, submission_id: str, team_id: int | None) -> bytes | None:
        """The body when the board is fresh and holds this team's submission, else None."""
        with self._lock:
            if time.monotonic() - self._at >= self.ttl_s:
                return None
            found = self._bodies.get(submission_id)
        if found is None or found[0] != team_id:
            return None
        return found[1]

    def refresh(self, session: Session) -> None:
        """Rebuild the board unless another thread just did."""
        with self._refreshing:
            with self._lock:
                if time.monotonic() - self._at < self.ttl_s:
                    return
            started = time.monotonic()
            rows = session.execute(select(Submission, Team.name).join(
                Team, Team.id == Submission.team_id).where(
                Submission.state.in_([s.value for s in ACTIVE_STATES]))).all()
            bodies = {row.id: (row.team_id, self.render(session, row, name))
                      for row, name in rows}
            with self._lock:
                self._bodies = bodies
                self._at = started


__all__ = ["Render", "StatusBoard"]
