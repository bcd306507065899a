"""``hlvs schedule run``: APScheduler with its jobs in the SQLite state file, and the ledger.

On every start the runner (1) records the schedule and fixes the tournament's reference time in
the state file the first time, (2) adds new matches to the ledger, (3) puts back the steps a
killed run left half done (PULLING -> PLANNED, PLAYING -> PULLED, DELIVERING -> PLAYED), and
(4) keeps one APScheduler job for the next step of every unfinished match. Jobs whose time passed
while no scheduler ran fire once at start (coalesced) and decide themselves whether they are
still useful (a match whose stream started is marked MISSED with the reason).
"""

from __future__ import annotations

import logging
import math
import signal
import threading
import time
from datetime import UTC, datetime, timedelta
from pathlib import Path
from typing import Any

from apscheduler.events import (
    EVENT_JOB_ERROR,
    EVENT_JOB_EXECUTED,
    EVENT_JOB_MISSED,
    EVENT_JOB_SUBMITTED,
    JobEvent,
    JobExecutionEvent,
)
from apscheduler.executors.pool import ThreadPoolExecutor
from apscheduler.jobstores.sqlalchemy import SQLAlchemyJobStore
from apscheduler.schedulers.background import BackgroundScheduler

from orchestrator import ScheduleError
from orchestrator.config import Schedule, load_schedule, resolve_time
from tournament.controls import abort_request
from tournament.state import Ledger, MatchRow, ScheduledMatchState

log = logging.getLogger(__name__)
S = ScheduledMatchState

JOB_FUNCTIONS = {
    "pull": "tournament.jobs:pull_job",
    "play": "tournament.jobs:play_job",
    "deliver": "tournament.jobs:deliver_job",
}
NEXT_STEP = {
    S.PLANNED: ("pull", "pull_at"),
    S.PULLED: ("play", "play_at"),
    S.PLAYED: ("deliver", "deliver_at"),
    S.LOGS_PENDING: ("deliver", "deliver_at"),  # a retry, at not_before
}
INTERRUPTED = {S.PULLING: S.PLANNED, S.PLAYING: S.PULLED, S.DELIVERING: S.PLAYED}


def init_state(
    schedule_path: str | Path,
    state_path: str | Path,
    *,
    services: str | None = None,
    now: datetime | None = None,
    pool: str | None = None,
) -> tuple[Schedule, Ledger]:
    """Open (or create) the state file of a schedule and add its matches to the ledger.

    The first run records the file's content in the state file: later runs (restarts) run that
    recorded copy and only warn when the file was edited; 'hlvs schedule apply' applies it."""
    ledger = Ledger(Path(state_path))
    recorded = ledger.get_meta("schedule")
    if recorded is not None and Path(recorded) != Path(schedule_path).resolve():
        raise ScheduleError(
            f"{state_path} belongs to the schedule {recorded}, not {schedule_path}; "
            "use another --state file"
        )
    recorded_text = ledger.get_meta("schedule_text")
    if recorded_text is None:
        schedule = load_schedule(schedule_path)
        ledger.set_meta("schedule_text", Path(schedule_path).read_text(encoding="utf-8"))
    else:
        schedule = load_schedule(schedule_path, text=recorded_text)
    ledger.set_meta("schedule", str(schedule.source))
    reference_text = ledger.get_meta("reference")
    if reference_text is None:
        now = now or datetime.now(UTC)
        if schedule.start in (None, "now"):
            reference = now
        else:
            reference = resolve_time(str(schedule.start), now)
        ledger.set_meta("reference", reference.isoformat())
    else:
        reference = datetime.fromisoformat(reference_text)
    if services is not None:
        ledger.set_meta("services", services)
    if pool is not None:
        ledger.set_meta("pool", pool)
    for planned in schedule.plan(reference):
        added = ledger.ensure(
            {
                "id": planned.match.id,
                "kind": planned.match.kind,
                "red": str(planned.match.red),
                "blue": str(planned.match.blue),
                "pull_at": planned.pull_at.isoformat(),
                "play_at": planned.play_at.isoformat(),
                "stream_start": planned.stream_start.isoformat(),
                "stream_end": planned.stream_end.isoformat(),
                "deliver_at": planned.deliver_at.isoformat(),
            }
        )
        if added:
            log.info(
                "match %s planned: pull %s, stream %s",
                planned.match.id,
                planned.pull_at.isoformat(timespec="seconds"),
                planned.stream_start.isoformat(timespec="seconds"),
            )
    from tournament.controls import file_differences

    for note in file_differences(ledger):
        log.warning("%s", note)
    return schedule, ledger


def recover_interrupted(ledger: Ledger) -> list[str]:
    """Put back the steps that a killed scheduler left half done; returns the match ids."""
    recovered = []
    for row in ledger.rows():
        back = INTERRUPTED.get(row.state)
        if row.state is S.PLAYING and abort_request(row.request) is not None:
            reason = abort_request(row.request)
            assert reason is not None
            if ledger.transition(row.id, (S.PLAYING,), S.ABORTED,
                                 note=f"aborted by the operator: {reason[0]}"):
                ledger.set_request(row.id, None)
                recovered.append(row.id)
            continue
        if row.state is S.DELIVERING and any(e.state in ("retrying", "failed") for e in row.logs):
            back = S.LOGS_PENDING  # a retry was interrupted
        if back is not None and ledger.transition(
            row.id, (row.state,), back, note=f"{row.state.value} interrupted by a restart"
        ):
            log.warning("match %s: %s was interrupted; back to %s", row.id, row.state, back)
            recovered.append(row.id)
    return recovered


class RunningJobs:
    """The jobs handed to an executor and not finished: running, or queued for a simulator
    slot. A queued job is not in APScheduler's store any more; adding it again would make
    APScheduler skip it ("maximum number of running instances reached") at every pass."""

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._count: dict[str, int] = {}

    def listen(self, event: JobEvent) -> None:
        # a counter: a job may finish before its submission event is dispatched
        step = 1 if event.code == EVENT_JOB_SUBMITTED else -1
        with self._lock:
            count = self._count.get(event.job_id, 0) + step
            if count:
                self._count[event.job_id] = count
            else:
                self._count.pop(event.job_id, None)

    def ids(self) -> set[str]:
        with self._lock:
            return {job_id for job_id, count in self._count.items() if count > 0}


class _OncePerMinute(logging.Filter):
    """APScheduler's "skipped: maximum number of running instances reached" once a minute per
    job at most (it may repeat every second while a match waits for a simulator slot)."""

    def __init__(self) -> None:
        super().__init__()
        self._last: dict[str, float] = {}

    def filter(self, record: logging.LogRecord) -> bool:
        if "maximum number of running instances" not in record.msg:
            return True
        job = record.args[0] if isinstance(record.args, tuple) and record.args else None
        key = str(getattr(job, "id", job))  # the job's id, not its text (it has its next run)
        now = time.monotonic()
        if now - self._last.get(key, -math.inf) < 60.0:
            return False
        self._last[key] = now
        return True


def reconcile(scheduler: Any, ledger: Ledger, state_path: str,
              running: set[str] | None = None) -> None:
    """One job for the next step of every unfinished match (none while a step runs or waits
    for its executor: ``running``)."""
    for row in ledger.rows():
        step = NEXT_STEP.get(row.state)
        if step is None:
            continue
        kind, attr = step
        job_id = f"{kind}:{row.id}"
        if running and job_id in running:
            continue
        run_at: datetime = getattr(row, attr)
        if row.not_before is not None and row.not_before > run_at:
            run_at = row.not_before
        job = scheduler.get_job(job_id)
        if job is not None and not _moved(job.next_run_time, run_at):
            continue
        scheduler.add_job(
            JOB_FUNCTIONS[kind],
            "date",
            run_date=run_at,
            args=[state_path, row.id],
            id=job_id,
            name=f"{kind} {row.id}",
            executor="play" if kind == "play" else "default",
            misfire_grace_time=None,
            coalesce=True,
            replace_existing=True,
        )


def _moved(planned: datetime | None, wanted: datetime) -> bool:
    """A rescheduled match's job is moved, unless it is due (the scheduler may be running it
    right now; a job that fires early finds its step not due and the next pass adds it again)."""
    if planned is None:
        return True
    now = datetime.now(UTC)
    return abs((planned - wanted).total_seconds()) > 1.0 and planned > now + timedelta(seconds=2)


def _stop_now(stop: threading.Event, wake: threading.Event) -> None:
    from tournament.jobs import STOPPING

    STOPPING.set()
    stop.set()
    wake.set()


class TournamentScheduler(BackgroundScheduler):  # type: ignore[misc]
    """APScheduler's background scheduler with a shutdown that never meets a pass over the
    job store half done.

    APScheduler removes a one-time job from its store after handing it to an executor; a
    shutdown in between (a quick job, ``deliver``, ended the tournament meanwhile) made that
    removal fail in the scheduler's thread (``JobLookupError``) and left the job in the state
    file. Here each pass runs under a lock of ours, after a check whether the scheduler
    closes: :meth:`close` takes the lock (waiting for a pass under way), marks the scheduler
    closing, and only then shuts it down. (Pausing, then listing the jobs to wait for the
    pass, left a window: a pass that had checked for the pause but not yet taken the job
    stores' lock.)"""

    def __init__(self, **options: Any) -> None:
        super().__init__(**options)
        self._pass = threading.Lock()
        self._closing = False

    def _process_jobs(self) -> float | None:
        with self._pass:
            if self._closing:
                return None  # until the shutdown's wake-up
            wait: float | None = super()._process_jobs()
            return wait

    def close(self, *, wait: bool) -> None:
        """Shut down once no pass over the job store is under way (``wait``: for the running
        jobs too, as :meth:`shutdown`)."""
        with self._pass:
            self._closing = True
        self.shutdown(wait=wait)

    def alive(self) -> bool:
        """Whether the scheduler's thread still runs. An error APScheduler does not catch in
        its pass over the job store (the state file busy beyond SQLite's timeout while it
        removes a job, say) ends that thread, and the scheduler would go on looking as if it
        ran: nothing would be started again, silently."""
        thread = getattr(self, "_thread", None)  # BackgroundScheduler's thread (APScheduler 3)
        return thread is None or thread.is_alive()


def _scheduler(state: str, slots: int, running: RunningJobs,
               wake: threading.Event) -> TournamentScheduler:
    """The job scheduler of the state file ``state``: ``slots`` matches played at once; the
    jobs running kept in ``running``, ``wake`` set when one ended (its match may have a next
    step now)."""
    scheduler = TournamentScheduler(
        jobstores={"default": SQLAlchemyJobStore(url=f"sqlite:///{state}")},
        executors={
            "default": ThreadPoolExecutor(2),
            "play": ThreadPoolExecutor(slots),
        },
        timezone=UTC,
    )

    def job_done(event: JobExecutionEvent) -> None:
        if event.exception is not None:
            log.error("job %s failed: %r", event.job_id, event.exception)
        wake.set()

    scheduler.add_listener(running.listen, EVENT_JOB_SUBMITTED | EVENT_JOB_EXECUTED
                           | EVENT_JOB_ERROR | EVENT_JOB_MISSED)
    scheduler.add_listener(job_done, EVENT_JOB_EXECUTED | EVENT_JOB_ERROR)
    return scheduler


def _restarted(old: TournamentScheduler, state: str, slots: int, running: RunningJobs,
               wake: threading.Event) -> TournamentScheduler:
    """A new scheduler on the same state file in place of ``old``, whose thread ended. The steps
    ``old`` runs go on in its executors (``running`` still follows them); a job it left in the
    store runs again, and its step finds itself done (each step moves the match's state on
    only from where it expects it)."""
    log.error("the job scheduler's thread ended (its error is above); starting a new one on "
              "%s", state)
    try:
        old.shutdown(wait=False)
    except Exception:  # noqa: BLE001 - the dead scheduler's own state: the new one is what counts
        log.exception("the ended scheduler did not shut down cleanly")
    scheduler = _scheduler(state, slots, running, wake)
    scheduler.start()
    return scheduler


def _print_changes(rows: list[MatchRow], last: dict[str, str]) -> None:
    """Print each match whose state changed since ``last`` (updated), one line each."""
    for row in rows:
        if last.get(row.id) != row.state.value:
            last[row.id] = row.state.value
            print(
                f"{datetime.now(UTC).isoformat(timespec='seconds')} {row.id}: "
                f"{row.state.value} {row.note}".rstrip(),
                flush=True,
            )


def run_schedule(
    schedule_path: str | Path,
    state_path: str | Path,
    *,
    services: str | None = None,
    pool: str | None = None,
    exit_when_done: bool = False,
    poll_s: float = 1.0,
    stop: threading.Event | None = None,
    stop_grace_s: float | None = None,
    notify: str | None = None,
) -> int:
    """Run the tournament until every match is final (with ``exit_when_done``) or a signal.

    SIGTERM or SIGINT stops it: a playing match gets SIGTERM (it stops and collects what was
    played), SIGKILL after ``stop_grace_s`` (default :data:`tournament.jobs.DEFAULT_STOP_GRACE_S`,
    kept in the state file), stays PLAYING marked interrupted, and is played again at the next
    start. The call returns once the running steps ended (or a little after the grace period).

    ``notify``: the operators' notification settings
    (:meth:`tournament.notify.NotifySettings.recorded`), kept in the state file; the scheduler
    writes its heartbeat there and sends the notices (:mod:`tournament.notify`)."""
    from tournament.jobs import STOPPING, settle_hand_deliveries
    from tournament.notify import HEARTBEAT_S, beat, stopped

    STOPPING.clear()
    state = str(Path(state_path).resolve())
    schedule, ledger = _open_state(schedule_path, state, services=services, pool=pool,
                                   stop_grace_s=stop_grace_s, notify=notify)  # fmt: skip
    stop = stop or threading.Event()
    wake = threading.Event()
    if threading.current_thread() is threading.main_thread():
        for sig in (signal.SIGINT, signal.SIGTERM):
            signal.signal(sig, lambda *_: _stop_now(stop, wake))
    running = RunningJobs()
    scheduler = _scheduler(state, schedule.simulator_slots, running, wake)
    quiet = _OncePerMinute()
    logging.getLogger("apscheduler.scheduler").addFilter(quiet)
    scheduler.start()
    log.info(
        "schedule %s: %d matches, %d simulator slot(s), state in %s",
        schedule.name,
        len(schedule.matches),
        schedule.simulator_slots,
        state,
    )
    last: dict[str, str] = {}
    notices = threading.Event()
    notifier = threading.Thread(target=_notify_loop, args=(ledger, notices), name="notices",
                                daemon=True)
    notifier.start()
    beaten = time.monotonic()
    try:
        while not stop.is_set():
            if time.monotonic() - beaten >= HEARTBEAT_S:
                beat(ledger)
                settle_hand_deliveries(ledger, schedule)  # hlvs logs deliver
                beaten = time.monotonic()
            if not scheduler.alive():
                scheduler = _restarted(scheduler, state, schedule.simulator_slots, running, wake)
            reconcile(scheduler, ledger, state, running.ids())
            rows = ledger.rows()
            _print_changes(rows, last)
            if exit_when_done and all(row.state.final for row in rows):
                break
            wake.wait(poll_s)
            wake.clear()
    finally:
        _shut_down(scheduler, running, ledger, stopped_by_user=stop.is_set())
        logging.getLogger("apscheduler.scheduler").removeFilter(quiet)
        notices.set()
        notifier.join(timeout=15)
        stopped(ledger)
    return 0


def _open_state(
    schedule_path: str | Path,
    state: str,
    *,
    services: str | None,
    pool: str | None,
    stop_grace_s: float | None,
    notify: str | None,
) -> tuple[Schedule, Ledger]:
    """The schedule and its state file, this run's settings kept in it, a first heartbeat
    written and the matches an earlier run left playing marked interrupted."""
    from tournament.notify import beat

    schedule, ledger = init_state(schedule_path, state, services=services, pool=pool)
    if stop_grace_s is not None:
        ledger.set_meta("stop_grace_s", repr(float(stop_grace_s)))
    if notify is not None:
        ledger.set_meta("notify", notify)
    beat(ledger)
    recover_interrupted(ledger)
    return schedule, ledger


def _shut_down(
    scheduler: TournamentScheduler, running: RunningJobs, ledger: Ledger, *, stopped_by_user: bool
) -> None:
    """Stop the scheduler. On SIGTERM or SIGINT the running steps get the stop grace (the
    state file's, else the default) and 15 s more to end; otherwise the scheduler waits for
    them unless ``stopped_by_user`` (the ``stop`` event)."""
    from tournament.jobs import DEFAULT_STOP_GRACE_S, STOPPING

    if STOPPING.is_set():
        scheduler.close(wait=False)
        grace = ledger.get_meta("stop_grace_s")
        _wait_for_steps(running, (float(grace) if grace else DEFAULT_STOP_GRACE_S) + 15.0)
    else:
        scheduler.close(wait=not stopped_by_user)


def _notify_loop(ledger: Ledger, done: threading.Event, every_s: float = 2.0) -> None:
    """Queue and send the operators' notices until ``done`` (then one last round)."""
    from tournament.notify import Outbox, recorded_settings

    settings = recorded_settings(ledger)
    if not settings.any:
        return
    outbox = Outbox(ledger, settings)
    while True:
        finished = done.wait(every_s)
        try:
            outbox.scan()
            outbox.send_due()
        except Exception:  # noqa: BLE001 - the notifier thread's boundary: retried next round
            log.exception("notices: a round failed; retrying")
        if finished:
            return


def _wait_for_steps(running: RunningJobs, timeout_s: float) -> None:
    """Wait for the steps in progress (a stopping match collects its logs) up to ``timeout_s``."""
    deadline = time.monotonic() + timeout_s
    if running.ids():
        log.info("waiting for %s to end", ", ".join(sorted(running.ids())))
    while running.ids() and time.monotonic() < deadline:
        time.sleep(0.1)
    if running.ids():
        log.warning("still running after %g s: %s; left to the next start", timeout_s,
                    ", ".join(sorted(running.ids())))
