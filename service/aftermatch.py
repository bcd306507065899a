"""After a test match ended: the delivery of the team's logs and the match's video, done by a
thread of the service outside the match.

Logs: when the team uploaded credentials (``PUT /v1/team/files/credentials``) before it
submitted, the worker marks the delivery ``pending`` as the match ends. This thread puts the
team's logs (``teams/red/`` of the match output, which stay downloadable from the service) in
the service's log store (``<data_dir>/log-store``) and uploads them to the team's SFTP or S3
target the way ``hlvs match`` delivers logs (:mod:`orchestrator.delivery`: files, then
``MANIFEST.json``, under ``<match_id>/<team>/``; transient failures retried with back-off). The
state becomes ``delivered`` or ``failed`` with the cause (wrong password, unknown host key,
bucket missing...); a failed set stays in the store, where ``hlvs logs deliver --store`` can
try it again.

When the worker ends a submission whose match left a replay, it marks the video ``pending``
(:class:`service.db.MediaState`). This thread renders it with ``hlvs render`` (the simulator's
offscreen renderer, which picks ``MUJOCO_GL`` itself) in a process of its own at the idle CPU
priority (``SCHED_IDLE``: a match playing meanwhile keeps its CPU), one render at a time,
into ``public/match.mp4`` of the match output (written under another name and renamed, so a
download never gets half a file). The state becomes ``ready``,
or ``failed`` with the cause; either way the submission's outcome stays what the match gave, and
the match was over before the render began, so a video never makes a match slower.

Restart safety: the render's pid and start time are kept in ``render.json`` of the match's work
folder. A later service process waits for a render that still runs, takes a video that is
there, and renders again (once) when an earlier render stopped without one.
"""

from __future__ import annotations

import functools
import json
import logging
import os
import shutil
import signal
import subprocess
import sys
import threading
import time
from collections.abc import Sequence
from dataclasses import dataclass
from datetime import UTC, datetime, timedelta
from pathlib import Path
from typing import TYPE_CHECKING

from sqlalchemy import select

from cluster import process_start_time
from contracts import files
from orchestrator import open_private_append, private_dir, write_private
from service import teamfiles
from service.db import MediaState, Submission, Team, TeamFile, transaction
from service.matchfiles import OWN_COLOR
from service.settings import LOG_TARGET_ALLOW_SETTING, log_target_networks

if TYPE_CHECKING:
    from sqlalchemy.orm import Session, sessionmaker

    from cluster import MatchPool
    from service.sealing import Sealer
    from service.settings import Settings

log = logging.getLogger(__name__)

VIDEO_FILE = files.VIDEO
PARTIAL_VIDEO_FILE = "match.partial.mp4"  # ffmpeg picks the format from the extension
RENDER_STATE = "render.json"
RENDER_LOG = "render.log"
MAX_RENDERS = 2  # renders of one video (a second one after a restart killed the first)
POLL_S = 1.0
RENDER_PER_MATCH_S = 5.0
"""Seconds of render per second the match played, until a render of this service process was
timed (then that one's ratio): the pending video's detail says when it is expected."""


LOG_STORE = "log-store"  # in the service's data folder
CREDENTIALS_FILE = "credentials.json"  # the submission's credentials, in its work folder


def team_logs_of(out: Path, color: str) -> Path:
    return out / "teams" / color


def replay_of(out: Path) -> Path:
    return out / "public" / files.REPLAY


def video_of(out: Path) -> Path:
    return out / "public" / VIDEO_FILE


@dataclass
class _Render:
    submission_id: str
    process: subprocess.Popen[bytes]
    started: float
    partial: Path
    video: Path
    work: Path  # the match's work folder (render log and state)


class AfterMatch:
    def __init__(
        self, *, settings: Settings, sessions: sessionmaker[Session], pool: MatchPool,
        sealer: Sealer, python: str = sys.executable,
    ) -> None:
        self.settings = settings
        self._sessions = sessions
        self._pool = pool
        self._sealer = sealer
        self.python = python
        self._render: _Render | None = None
        self._render_per_match_s = RENDER_PER_MATCH_S
        self._stop = threading.Event()
        self._wake = threading.Event()
        self._thread: threading.Thread | None = None

    # lifecycle ---------------------------------------------------------------------------
    def start(self) -> None:
        self._thread = threading.Thread(target=self._run, name="after-match", daemon=True)
        self._thread.start()

    def stop(self) -> None:
        """Stop the thread and a render under way (the renderer and its ffmpeg: nothing of the
        service outlives it); the next start renders that video again, not counting the
        stopped render against :data:`MAX_RENDERS`."""
        self._stop.set()
        self._wake.set()
        if self._thread is not None:
            self._thread.join(timeout=30)
        render, self._render = self._render, None
        if render is not None and render.process.poll() is None:
            _stop_group(render.process)
            render.partial.unlink(missing_ok=True)
            state = _read_json(render.work / RENDER_STATE)
            renders = state.get("renders")
            if isinstance(renders, int):
                (render.work / RENDER_STATE).write_text(json.dumps(
                    {"renders": max(0, renders - 1)}))
            log.info("submission %s: render stopped with the service", render.submission_id)

    def wake(self) -> None:
        self._wake.set()

    def _run(self) -> None:
        while not self._stop.is_set():
            try:
                self.round()
            except Exception:  # the thread's boundary: log, keep serving
                log.exception("after-match round failed; retrying")
            self._wake.wait(POLL_S)
            self._wake.clear()

    # one round ---------------------------------------------------------------------------
    def round(self) -> None:
        self._deliveries()
        with transaction(self._sessions) as session:
            pending = list(session.scalars(select(Submission).where(
                Submission.video_state == MediaState.PENDING.value).order_by(Submission.seq)))
            render = self._render
            if render is not None and render.submission_id not in {r.id for r in pending} \
                    and render.process.poll() is not None:
                self._render = None  # its submission was requeued meanwhile
            for row in pending:
                self._video(row)
            self._expect([row for row in pending if row.video_state == MediaState.PENDING.value])

    # logs ----------------------------------------------------------------------------------
    def _deliveries(self) -> None:
        """Every pending delivery, oldest first; the uploads run outside any transaction."""
        with transaction(self._sessions) as session:
            rows = session.execute(select(Submission, Team.name, TeamFile.content).join(
                Team, Team.id == Submission.team_id).outerjoin(
                TeamFile, TeamFile.id == Submission.credentials_file_id).where(
                Submission.delivery_state == MediaState.PENDING.value).order_by(
                Submission.seq)).all()
            jobs = [(row.seq, row.id, row.match_id, row.pool_handle, team, content)
                    for row, team, content in rows]
        for seq, sid, match_id, handle, team, content in jobs:
            if self._stop.is_set():
                return
            state, detail = self._deliver(match_id, handle, team, content)
            with transaction(self._sessions) as session:
                row = session.get(Submission, seq)
                if row is not None and row.delivery_state == MediaState.PENDING.value:
                    row.delivery_state, row.delivery_detail = state.value, detail
            log.log(logging.WARNING if state is MediaState.FAILED else logging.INFO,
                    "submission %s: logs %s (%s)", sid, state.value, detail)

    def _deliver(self, match_id: str | None, handle: str | None, team: str,
                 content: str | None) -> tuple[MediaState, str]:
        """Deliver the team's logs; the detail the team sees. A target's address obeys the
        webhooks' rules (``HLVS_SERVICE_LOG_TARGET_ALLOW``), checked again here and pinned
        for the connection; what a server answered (an error body, a host key) is never in
        the detail, only the kind of failure (the service's log has the whole cause)."""
        from orchestrator.delivery import (
            ERROR_KINDS,
            deliver_pending,
            enqueue_match_logs,
            list_sets,
            open_uploader,
        )

        if match_id is None or handle is None or content is None:
            return MediaState.FAILED, "the match left no logs, or no credentials were given"
        allowed = log_target_networks(self.settings)
        document = self._sealer.open_document("credentials", json.loads(content))
        _, refused = teamfiles.service_problems("credentials", document, allowed=allowed)
        if refused:  # stored before the service's rules: never read the host's files for it
            return MediaState.FAILED, str(refused[0]).replace(refused[0].file, CREDENTIALS_FILE)
        out = self._pool.results_dir(handle)
        work = private_dir((self.settings.matches_dir / match_id).resolve())
        credentials = write_private(work / CREDENTIALS_FILE, json.dumps(document))
        store = private_dir(self.settings.data_dir.resolve() / LOG_STORE)
        if not any(s.match_id == match_id and s.team == team for s in list_sets(store)):
            made = enqueue_match_logs(out, match_id=match_id,
                                      teams={OWN_COLOR: (team, credentials)},
                                      public_target=None, store=store, move_team_logs=False)
            if not made:
                return MediaState.FAILED, "the team's robots left no log files"
        opener = functools.partial(open_uploader, allowed=allowed,
                                   allow_setting=LOG_TARGET_ALLOW_SETTING)
        outcomes = [o for o in deliver_pending(store, team=team, opener=opener)
                    if o.match_id == match_id]
        if not outcomes:
            return MediaState.FAILED, "the log set is being delivered by another process"
        outcome = outcomes[-1]
        if outcome.delivered:
            return MediaState.DELIVERED, (
                f"{outcome.uploaded_files} file(s) uploaded ({outcome.skipped_files} already "
                f"there), {outcome.uploaded_bytes / 1e6:.2f} MB to {outcome.target}/{match_id}/"
                f"{team} in {outcome.seconds:.1f} s")
        error = outcome.error
        if error is None:
            cause = "unknown error"
        elif error.kind == "address":
            cause = f"{error.kind}: {error.reason}"  # the service's own words, no answer
        else:
            cause = f"{error.kind}: {ERROR_KINDS.get(error.kind, 'failed')}"
        return MediaState.FAILED, (f"upload to {outcome.target} failed ({cause}); the logs "
                                   "wait in the service's log store")

    # video ---------------------------------------------------------------------------------
    def _work_dir(self, row: Submission) -> Path:
        assert row.match_id is not None
        return (self.settings.matches_dir / row.match_id).resolve()

    def _video(self, row: Submission) -> None:
        if row.pool_handle is None or row.match_id is None:
            self._set(row, MediaState.FAILED, "the match left no output")
            return
        out = self._pool.results_dir(row.pool_handle)
        work = self._work_dir(row)
        render = self._render
        if render is not None and render.submission_id == row.id:
            self._follow(row, render, work)
            return
        video = video_of(out)
        if video.is_file():  # rendered while an earlier service process ran
            self._set(row, MediaState.READY, f"{video.stat().st_size} bytes")
            return
        if not replay_of(out).is_file():
            self._set(row, MediaState.FAILED, "the match left no replay")
            return
        if render is not None:
            return  # one render at a time: this one waits
        state = _read_json(work / RENDER_STATE)
        pid, recorded = state.get("pid"), state.get("start_time")
        if isinstance(pid, int) and recorded is not None and \
                process_start_time(pid) == recorded:
            return  # an earlier service process's render still runs
        count = state.get("renders", 0)
        renders = count if isinstance(count, int) else 0
        if renders >= MAX_RENDERS:
            self._set(row, MediaState.FAILED, f"{renders} renders stopped without a video"
                      + _tail(work / RENDER_LOG))
            return
        self._start(row, out, work, renders + 1)

    def _start(self, row: Submission, out: Path, work: Path, renders: int) -> None:
        s = self.settings
        partial = out / "public" / PARTIAL_VIDEO_FILE
        partial.unlink(missing_ok=True)
        command = [*_idle_priority(), self.python, "-m", "simulator", "render",
                   str(replay_of(out)), "-o", str(partial), "--width", str(s.video_width),
                   "--height", str(s.video_height), "--fps", f"{s.video_fps:g}"]
        private_dir(work)
        env = {**os.environ, "HLVS_PROGRESS": "plain", "HLVS_PROG": "hlvs"}
        with os.fdopen(open_private_append(work / RENDER_LOG), "ab") as log_file:
            try:
                process = subprocess.Popen(command, stdout=log_file, stderr=subprocess.STDOUT,
                                           stdin=subprocess.DEVNULL, env=env,
                                           start_new_session=True)
            except OSError as exc:
                self._set(row, MediaState.FAILED, f"hlvs render could not start: {exc}")
                return
        write_private(work / RENDER_STATE, json.dumps({
            "pid": process.pid, "start_time": process_start_time(process.pid),
            "renders": renders}))
        self._render = _Render(submission_id=row.id, process=process, started=time.monotonic(),
                               partial=partial, video=video_of(out), work=work)
        log.info("submission %s: rendering the video of match %s (pid %d)", row.id,
                 row.match_id, process.pid)

    def _follow(self, row: Submission, render: _Render, work: Path) -> None:
        code = render.process.poll()
        elapsed = time.monotonic() - render.started
        if code is None:
            if elapsed > self.settings.video_timeout_s:
                try:
                    os.killpg(render.process.pid, signal.SIGKILL)  # the renderer and ffmpeg
                except ProcessLookupError:
                    pass
                render.process.wait()
                self._render = None
                self._set(row, MediaState.FAILED, f"the render took more than "
                          f"{self.settings.video_timeout_s:g} s and was stopped")
            return
        self._render = None
        if code == 0 and render.partial.is_file():
            render.partial.replace(render.video)
            played_s = _played_s(row)
            if played_s is not None and played_s > 0:
                self._render_per_match_s = elapsed / played_s
            s = self.settings
            self._set(row, MediaState.READY, f"{render.video.stat().st_size} bytes, "
                      f"{s.video_width}x{s.video_height} at {s.video_fps:g} fps, rendered "
                      f"in {elapsed:.0f} s")
            return
        render.partial.unlink(missing_ok=True)
        out = render.video.parent.parent
        self._set(row, MediaState.FAILED, f"hlvs render exited with code {code}"
                  + _tail(work / RENDER_LOG).replace(f"{out}/", ""))

    def _expect(self, pending: Sequence[Submission]) -> None:
        """Each pending video's detail says when it is expected: the render under way first,
        then the others in their order, each taking its match's length times the ratio."""
        render = self._render
        rendering = render.submission_id if render is not None else None
        queue = sorted(pending, key=lambda r: r.id != rendering)  # stable: the rest in order
        details = pending_details(
            [(row.id, _played_s(row) or self.settings.expected_match_s) for row in queue],
            now=datetime.now(UTC), rendering_id=rendering,
            rendering_elapsed_s=time.monotonic() - render.started if render is not None else 0.0,
            render_per_match_s=self._render_per_match_s)
        for row in queue:
            if row.video_detail != details[row.id]:
                row.video_detail = details[row.id]

    def _set(self, row: Submission, state: MediaState, detail: str) -> None:
        row.video_state = state.value
        row.video_detail = detail
        log.log(logging.WARNING if state is MediaState.FAILED else logging.INFO,
                "submission %s: video %s (%s)", row.id, state.value, detail)


def _played_s(row: Submission) -> float | None:
    """The match's wall time, start to end (the length of its replay, near enough)."""
    if row.started_at is None or row.finished_at is None:
        return None
    return max(0.0, (row.finished_at - row.started_at).total_seconds())


def pending_details(queue: Sequence[tuple[str, float]], *, now: datetime,
                    rendering_id: str | None, rendering_elapsed_s: float,
                    render_per_match_s: float) -> dict[str, str]:
    """The detail of each pending video, by submission id: when its render is expected to end
    (to the minute, UTC). ``queue``: (submission id, the match's wall seconds) in render
    order, the render under way (``rendering_id``, running ``rendering_elapsed_s``) first."""
    details: dict[str, str] = {}
    at = now
    for ahead, (submission_id, played_s) in enumerate(queue):
        estimate_s = played_s * render_per_match_s
        if submission_id == rendering_id:
            started = now - timedelta(seconds=rendering_elapsed_s)
            at = now + timedelta(seconds=max(estimate_s - rendering_elapsed_s, 60.0))
            details[submission_id] = (f"rendering since {started:%H:%M} UTC; expected by about "
                                      f"{_minute(at)} UTC")
            continue
        at += timedelta(seconds=estimate_s)
        waiting = "next" if ahead == 0 else f"{ahead} ahead of it"
        details[submission_id] = (f"waiting for the render ({waiting}); expected by about "
                                  f"{_minute(at)} UTC")
    return details


def _minute(at: datetime) -> str:
    """``at`` rounded up to the minute, as HH:MM (a promise kept rather than missed)."""
    up = at + timedelta(seconds=59.999)
    return f"{up:%H:%M}"


def _stop_group(process: subprocess.Popen[bytes], timeout_s: float = 5.0) -> None:
    """SIGTERM to the process group (the renderer and ffmpeg), SIGKILL when it lingers."""
    for sig in (signal.SIGTERM, signal.SIGKILL):
        try:
            os.killpg(process.pid, sig)
        except ProcessLookupError:
            return
        try:
            process.wait(timeout=timeout_s)
            return
        except subprocess.TimeoutExpired:
            continue


def _idle_priority() -> list[str]:
    """Run at the idle CPU priority (SCHED_IDLE: CPU time nothing else wants, so a match
    playing meanwhile is not slowed), or at the lowest nice level without ``chrt``."""
    return ["chrt", "--idle", "0"] if shutil.which("chrt") else ["nice", "-n", "19"]


def _read_json(path: Path) -> dict[str, object]:
    try:
        data = json.loads(path.read_text())
    except (OSError, ValueError):
        return {}
    return data if isinstance(data, dict) else {}


def _tail(path: Path) -> str:
    """': <the last line of the log>' ('' when there is none)."""
    try:
        lines = [line for line in path.read_text(errors="replace").splitlines() if line.strip()]
    except OSError:
        return ""
    return f": {lines[-1][-300:]}" if lines else ""


__all__ = [
    "AfterMatch",
    "CREDENTIALS_FILE",
    "LOG_STORE",
    "PARTIAL_VIDEO_FILE",
    "VIDEO_FILE",
    "replay_of",
    "team_logs_of",
    "video_of",
]
