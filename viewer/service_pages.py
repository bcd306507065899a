"""The viewer inside ``hlvs serve``: replays and live views of a team's own test matches.

Mounted by ``hlvs.app``. Replay and live ids are submission ids; every route
needs the team's token (``Authorization: Bearer``; the pages keep it in the browser's local
storage), and another team's submission answers 404 like an unknown one. The pages for the
queue, submissions, schedule and standings and the pool are the same front end, reading the
service's own ``/v1`` API with that token.
"""

from __future__ import annotations

from pathlib import Path

from fastapi import FastAPI, Request
from sqlalchemy import select

from contracts import files
from service import submissions
from service.db import Submission
from service.deps import DbSession, TeamPrincipal, get_services
from service.errors import NotFound
from service.ladder import watchable
from viewer.api import mount_viewer
from viewer.sources import LiveSource, ReplaySource, live_of

REPLAY = Path("public") / files.REPLAY
STATS = Path("public") / files.API_STATS


def _match_dir(request: Request, row: Submission) -> Path | None:
    pool = get_services(request).pool
    if row.pool_handle is None or pool is None:
        return None
    out: Path = pool.results_dir(row.pool_handle)
    return out


def _replay_of(row: Submission, out: Path | None) -> ReplaySource | None:
    if out is None or not (out / REPLAY).is_file():
        return None
    stats = out / STATS
    return ReplaySource(id=row.id, path=out / REPLAY, stats_path=stats if stats.is_file() else None)


class SubmissionResolver:
    def replay(self, replay_id: str, request: Request, principal: TeamPrincipal,
               session: DbSession) -> ReplaySource:
        assert principal.team_id is not None
        row = watchable(session, team_id=principal.team_id, team_name=principal.team_name,
                        submission_id=replay_id)  # a friendly's opponent watches it too
        source = _replay_of(row, _match_dir(request, row))
        if source is None:
            raise NotFound(what="replay of submission", ident=f"{row.id} ({row.state})")
        return source

    def live(self, match_id: str, request: Request, principal: TeamPrincipal,
             session: DbSession) -> LiveSource:
        assert principal.team_id is not None
        row = submissions.get_own(session, team_id=principal.team_id, submission_id=match_id)
        out = _match_dir(request, row)
        live = live_of(out, id=row.id) if out is not None and row.state == "running" else None
        if live is None:
            raise NotFound(what="running match of submission", ident=f"{row.id} ({row.state})")
        return live

    def listing(self, request: Request, principal: TeamPrincipal, session: DbSession
                ) -> tuple[list[ReplaySource], list[LiveSource]]:
        rows = session.scalars(select(Submission).where(Submission.team_id == principal.team_id)
                               .order_by(Submission.seq.desc()))
        replays, live = [], []
        for row in rows:
            out = _match_dir(request, row)
            source = _replay_of(row, out)
            if source is not None:
                replays.append(source)
            elif out is not None and row.state == "running":
                running = live_of(out, id=row.id)
                if running is not None:
                    live.append(running)
        return replays, live


def mount(app: FastAPI) -> None:
    mount_viewer(app, SubmissionResolver())
