"""The queue worker: starts queued test matches in the pool and follows them to their end.

One thread in the service process. Each round it (1) reconciles every STARTING / RUNNING
submission with the pool (this is also what a restarted service does first), (2) starts the
oldest queued submissions while the pool has free slots and the queue is not paused. Every
state change and its notifications are written in one transaction (the notifications are an
outbox sent by :mod:`service.notify`).

Restart safety: STARTING is committed before the pool is asked, with the match id the pool
will use. A STARTING submission found later is submitted again: the pool answers with the
running match when it did start (no duplicate); a match the pool lost (no process, no report)
is queued again at its old place, with a new attempt number (nothing is lost).
"""

from __future__ import annotations

import logging
import threading
import zlib
from collections.abc import Callable
from dataclasses import replace
from pathlib import Path
from typing import TYPE_CHECKING

from sqlalchemy import func, select
from sqlalchemy.orm import Session

from cluster import JobState, JobStatus, MatchJob, PoolError
from contracts import ContractError, FailureClass, MatchReport, files
from service import matchfiles, notify, teamfiles
from service.accounts import ensure_team_account, supports_accounts
from service.aftermatch import replay_of, team_logs_of
from service.db import MediaState, Submission, SubmissionState, Team, now, transaction
from service.errors import NotFound, ServiceError
from service.ladder import is_fixture
from service.matchfiles import OWN_COLOR
from service.results import MatchSummary, backfill, read_results, record, stored, teams_of
from service.submissions import STUB, failure_side, queue_paused

if TYPE_CHECKING:
    from sqlalchemy.orm import sessionmaker

    from cluster import MatchPool
    from orchestrator.config import TeamDocument
    from service.sealing import Sealer
    from service.services import Background
    from service.settings import Settings

log = logging.getLogger(__name__)

MAX_ATTEMPTS = 3


class _Refused(Exception):
    def __init__(self, cause: str, failure_class: str) -> None:
        super().__init__(cause)
        self.cause = cause
        self.failure_class = failure_class


class QueueWorker:
    def __init__(
        self, *, settings: Settings, pool: MatchPool, sessions: sessionmaker[Session],
        sealer: Sealer, changed: Callable[[str | None], None],
        aftermatch: Background | None = None,
    ) -> None:
        """``changed``: told of each submission changed (None: the queue as a whole);
        ``aftermatch``: woken when a match has ended."""
        self.settings = settings
        self.pool = pool
        self._sessions = sessions
        self._sealer = sealer
        self._changed = changed
        self._aftermatch = aftermatch
        self._stub_image = settings.stub_image or None
        self._stop = threading.Event()
        self._wake = threading.Event()
        self._thread: threading.Thread | None = None
        self._cancel_sent: set[str] = set()
        self._backfilled = False  # the results of matches ended before the results tables
        self.notifier = notify.Notifier(settings=settings, sessions=sessions, sealer=sealer)

    # lifecycle ---------------------------------------------------------------------------
    def start(self) -> None:
        self._thread = threading.Thread(target=self._run, name="queue-worker", daemon=True)
        self._thread.start()
        self.notifier.start()

    def stop(self) -> None:
        self._stop.set()
        self._wake.set()
        if self._thread is not None:
            self._thread.join(timeout=30)
        self.notifier.stop()

    def wake(self) -> None:
        """Run a round now (after a submission, a cancel or a resume)."""
        self._wake.set()

    def _run(self) -> None:
        while not self._stop.is_set():
            try:
                if self.round():
                    self._changed(None)
            except Exception:  # process boundary of the worker thread: log, keep serving
                log.exception("queue worker round failed; retrying")
                self._changed(None)
            self._wake.wait(self.settings.worker_poll_s)
            self._wake.clear()

    # one round ---------------------------------------------------------------------------
    def round(self) -> bool:
        """One round; True when it changed a submission."""
        sessions = self._sessions
        changed = False
        if not self._backfilled:
            with transaction(sessions) as session:
                changed = backfill(session, self.pool.results_dir) > 0
            self._backfilled = True
        self._stub_if_needed()
        with transaction(sessions) as session:
            active = list(session.scalars(select(Submission).where(Submission.state.in_(
                [SubmissionState.STARTING.value, SubmissionState.RUNNING.value])).order_by(
                Submission.seq)))
            for row in active:
                before = (row.state, row.attempts, row.cancel_requested, row.pool_detail)
                self._follow(session, row)
                changed |= before != (row.state, row.attempts, row.cancel_requested,
                                      row.pool_detail)
        while not self._stop.is_set():
            self._stub_if_needed()
            with transaction(sessions) as session:
                if queue_paused(session):
                    return changed
                busy = session.scalar(select(func.count()).select_from(Submission).where(
                    Submission.state.in_([SubmissionState.STARTING.value,
                                          SubmissionState.RUNNING.value]))) or 0
                if busy >= self.pool.slots:
                    return changed
                queued = session.scalar(select(Submission).where(
                    Submission.state == SubmissionState.QUEUED.value).order_by(
                    Submission.seq).limit(1).with_for_update(skip_locked=True))
                if queued is None:
                    return changed
                changed = True
                row = queued
                row.state = SubmissionState.STARTING.value
                row.attempts += 1
                row.match_id = f"{row.id}-a{row.attempts}"
                row.cause = None
                try:
                    job = self._prepare(session, row)
                except _Refused as exc:  # a file stored before the service's rules
                    self._end(session, row, SubmissionState.FAILED, cause=exc.cause,
                              failure_class=exc.failure_class)
                    self._changed(row.id)
                    continue
                row.pool_handle = None
                seq = row.seq
            with transaction(sessions) as session:
                starting = session.get(Submission, seq)
                assert starting is not None
                self._submit(session, starting, job)
        return changed

    # helpers -----------------------------------------------------------------------------
    def _work_dir(self, match_id: str) -> Path:
        return (self.settings.matches_dir / match_id).resolve()

    def _stub_if_needed(self) -> None:
        """Find (or build) the stub image before the transaction that starts a match against
        it: a build takes minutes, and a transaction holds SQLite's write lock (every other
        request would wait, then fail with "database is locked")."""
        if self._stub_image is not None:
            return
        with transaction(self._sessions) as session:
            opponent = session.scalar(select(Submission.opponent).where(
                Submission.state.in_([SubmissionState.QUEUED.value,
                                      SubmissionState.STARTING.value])).order_by(
                Submission.seq).limit(1))
        if opponent == STUB:
            self._stub()

    def _stub(self) -> str:
        if self._stub_image is None:
            from orchestrator import project_image

            self._stub_image = project_image("stub")
        return self._stub_image

    def _prepare(self, session: Session, row: Submission) -> MatchJob:
        assert row.match_id is not None
        sealer = self._sealer
        team_doc = teamfiles.opened(teamfiles.get_by_id(session, row.team_file_id), sealer)
        opponent_doc: TeamDocument | None = None
        if row.opponent != STUB:
            other = session.scalar(select(Team).where(Team.name == row.opponent))
            assert other is not None
            current = teamfiles.current(session, team_id=other.id)
            if current is None:
                raise NotFound(what="uploaded file that passed its checks",
                               ident=f"{row.opponent}'s team_config.json")
            opponent_doc = teamfiles.opened(current, sealer)
        for doc, failure_class, whose in ((team_doc, "team_startup", "the team file"),
                                          (opponent_doc, "infrastructure", "the opponent's")):
            _, refused = teamfiles.service_problems("team_config", doc)
            if refused:  # never hand a match a host variable or a key-less ECR login
                raise _Refused(f"{whose} team_config.json: {refused[0].pointer}: "
                               f"{refused[0].message}", failure_class)
        work = self._work_dir(row.match_id)
        game = matchfiles.write_match(
            work / "config", match_id=row.match_id, team=team_doc, opponent=opponent_doc,
            stub_image=None if opponent_doc else self._stub(), settings=self.settings,
            seed=zlib.crc32(row.match_id.encode()))
        # test matches: a cluster pool plays one again after a node failure
        return MatchJob(match_id=row.match_id, game_path=game, work_dir=work, requeue=True,
                        robot_nodes=self._robot_nodes(game))

    def _robot_nodes(self, game: Path) -> int:
        """League placement: a node for each robot (0: dense placement)."""
        if self.settings.placement != "league":
            return 0
        from orchestrator.match import robots_in_game

        return robots_in_game(game)

    def _submit(self, session: Session, row: Submission, job: MatchJob) -> None:
        """Hand the match to the pool (under the team's account on a cluster); RUNNING once
        the pool runs it, STARTING with the pool's reason while the pool keeps it waiting."""
        try:
            if supports_accounts(self.pool):
                team = session.get(Team, row.team_id)
                assert team is not None
                job = replace(job, account=ensure_team_account(session, self.pool, team,
                                                               self.settings))
            handle = self.pool.submit(job)
        except PoolError as exc:
            log.error("submission %s: %s", row.id, exc)
            self._end(session, row, SubmissionState.FAILED, failure_class="infrastructure",
                      cause=str(exc))
            return
        row.pool_handle = handle
        try:
            status = self.pool.status(handle)
        except ServiceError as exc:
            log.warning("submission %s: pool status failed: %s", row.id, exc)
            return  # the next round asks again
        self._observe(session, row, status)

    def _observe(self, session: Session, row: Submission, status: JobStatus) -> None:
        """A match the pool has (pending or running): state and waiting reason from it."""
        if status.state is JobState.RUNNING and row.state == SubmissionState.STARTING.value:
            self._mark_running(session, row)
        row.pool_detail = (status.detail or None) if status.state is JobState.PENDING else None

    def _mark_running(self, session: Session, row: Submission) -> None:
        row.state = SubmissionState.RUNNING.value
        row.started_at = row.started_at or now()
        row.charged = not is_fixture(session, row.id)  # the ladder's matches are free
        notify.enqueue(session, row, "submission.started", self.settings)
        log.info("submission %s running as match %s", row.id, row.match_id)

    def _follow(self, session: Session, row: Submission) -> None:
        if row.pool_handle is None:  # STARTING when the service stopped: submit again
            if row.match_id is None:
                row.state = SubmissionState.QUEUED.value
                return
            game = self._work_dir(row.match_id) / "config" / "game.json"
            if game.is_file():
                job = MatchJob(match_id=row.match_id, game_path=game,
                               work_dir=self._work_dir(row.match_id), requeue=True,
                               robot_nodes=self._robot_nodes(game))
            else:
                job = self._prepare(session, row)
            self._submit(session, row, job)
            return
        try:
            status = self.pool.status(row.pool_handle)
        except ServiceError as exc:
            log.warning("submission %s: pool status failed: %s", row.id, exc)
            return
        if status.state in (JobState.RUNNING, JobState.PENDING):
            self._observe(session, row, status)
            if row.cancel_requested and row.id not in self._cancel_sent:
                self.pool.cancel(row.pool_handle)
                self._cancel_sent.add(row.id)
            return
        if status.state is JobState.FINISHED:
            self._finish(session, row)
            return
        # LOST: nothing runs and no report was written
        if row.cancel_requested:
            self._end(session, row, SubmissionState.CANCELLED, cause="cancelled by the team")
        elif row.attempts >= MAX_ATTEMPTS:
            self._end(session, row, SubmissionState.FAILED, failure_class="infrastructure",
                      cause=f"the pool lost the match {MAX_ATTEMPTS} times: {status.detail}")
        else:
            log.warning("submission %s: match %s lost (%s); queued again", row.id,
                        row.match_id, status.detail)
            row.state = SubmissionState.QUEUED.value
            row.pool_handle = None
            row.cause = f"attempt {row.attempts} lost by the pool: {status.detail}"

    def _finish(self, session: Session, row: Submission) -> None:
        assert row.pool_handle is not None
        out = self.pool.results_dir(row.pool_handle)
        try:
            report = MatchReport.load(out / files.REPORT)
        except ContractError as exc:
            report = MatchReport(status="failed", failure_class=FailureClass.INFRASTRUCTURE,
                                 cause=f"unreadable {files.REPORT}: {exc}")
        if report.failure_class is None:
            self._end(session, row, SubmissionState.DONE, cause=None)
        elif report.failure_class is FailureClass.INTERRUPTED and row.cancel_requested:
            self._end(session, row, SubmissionState.CANCELLED,
                      cause="cancelled by the team while running (stopped gracefully)")
        else:
            self._end(session, row, SubmissionState.FAILED,
                      failure_class=report.failure_class.value,
                      cause=report.cause or "the match failed", team=report.team)

    def _end(self, session: Session, row: Submission, state: SubmissionState, *,
             cause: str | None, failure_class: str | None = None,
             team: str | None = None) -> None:
        row.state = state.value
        row.finished_at = now()
        row.pool_detail = None
        row.cause = cause
        row.failure_class = failure_class
        row.failure_side = failure_side(failure_class, team, OWN_COLOR)
        out = self.pool.results_dir(row.pool_handle) if row.pool_handle is not None else None
        if out is not None and self.settings.video and state is not SubmissionState.CANCELLED \
                and replay_of(out).is_file():
            row.video_state = MediaState.PENDING.value
            row.video_detail = "waiting for the render"
        if out is not None and row.credentials_file_id is not None and \
                team_logs_of(out, OWN_COLOR).is_dir():
            row.delivery_state = MediaState.PENDING.value
            row.delivery_detail = "waiting to be uploaded"
        if self._aftermatch is not None and out is not None:
            self._aftermatch.wake()
        if row.failure_side == "league":
            row.charged = False  # the league's fault costs the team nothing
        self._cancel_sent.discard(row.id)
        event = {SubmissionState.DONE: "submission.finished",
                 SubmissionState.FAILED: "submission.failed",
                 SubmissionState.CANCELLED: "submission.cancelled"}[state]
        results = read_results(out) if out is not None else None
        if results is not None:  # read once, here; everything after reads the database
            record(session, row.id, MatchSummary.of(results, teams_of(session, row)))
        notify.enqueue(session, row, event, self.settings, results=stored(session, row.id))
        log.info("submission %s %s%s", row.id, state.value,
                 f" ({failure_class}: {cause})" if failure_class else "")


__all__ = ["MAX_ATTEMPTS", "QueueWorker"]
