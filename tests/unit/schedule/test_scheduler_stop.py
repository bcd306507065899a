"""The tournament's scheduler stops cleanly when a one-time job ends the tournament while the
scheduler is still between handing that job to its executor and removing it from the store."""

from __future__ import annotations

import threading
import time
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

import pytest
from apscheduler.executors.pool import ThreadPoolExecutor
from apscheduler.jobstores.memory import MemoryJobStore
from apscheduler.schedulers.background import BackgroundScheduler
from apscheduler.schedulers.base import STATE_RUNNING

from tournament.runner import TournamentScheduler


class _Watched(TournamentScheduler):  # type: ignore[misc]
    """The tournament's scheduler, telling when it is asked to close."""

    def __init__(self, **options: Any) -> None:
        super().__init__(**options)
        self.asked = threading.Event()

    def close(self, *, wait: bool) -> None:
        self.asked.set()
        super().close(wait=wait)


class _SlowToReturn(ThreadPoolExecutor):
    """Submits the job, then lets the scheduler go on (and remove it) only once it was asked
    to close or stopped: the stop always comes in between, however slow the machine."""

    def submit_job(self, job: Any, run_times: Any) -> None:
        super().submit_job(job, run_times)
        asked = getattr(self._scheduler, "asked", threading.Event())
        deadline = time.monotonic() + 10.0
        while (self._scheduler.state == STATE_RUNNING and not asked.is_set()
               and time.monotonic() < deadline):
            time.sleep(0.01)


def _job(done: threading.Event) -> None:
    done.set()


def _in_its_pass(monkeypatch: pytest.MonkeyPatch, kind: type[BackgroundScheduler]
                 ) -> tuple[BackgroundScheduler, list[BaseException | None]]:
    """A scheduler whose one-time job has run while the scheduler is still handing it over
    (before removing it from the store), and the exceptions of its threads."""
    failures: list[BaseException | None] = []
    monkeypatch.setattr(threading, "excepthook", lambda args: failures.append(args.exc_value))
    scheduler = kind(jobstores={"default": MemoryJobStore()},
                     executors={"default": _SlowToReturn(1)}, timezone=UTC)
    done = threading.Event()
    scheduler.add_job(_job, "date", run_date=datetime.now(UTC), args=[done], id="deliver:m1",
                      misfire_grace_time=None)
    scheduler.start()
    assert done.wait(10), "the job did not run"
    return scheduler, failures


@pytest.mark.parametrize("wait", [True, False])
def test_a_stop_during_the_schedulers_pass_waits_for_it(
        wait: bool, monkeypatch: pytest.MonkeyPatch) -> None:
    scheduler, failures = _in_its_pass(monkeypatch, _Watched)
    thread = scheduler._thread
    started = time.monotonic()
    scheduler.close(wait=wait)  # the scheduler is still in submit_job
    assert time.monotonic() - started < 5.0  # not the slow executor's 10 s deadline
    assert not thread.is_alive()  # shutdown joins the scheduler's thread
    assert failures == []
    assert scheduler._jobstores["default"].get_all_jobs() == []  # removed, not left for later


def test_a_plain_shutdown_there_fails_in_the_schedulers_thread(
        monkeypatch: pytest.MonkeyPatch) -> None:
    """What :meth:`TournamentScheduler.close` prevents (APScheduler 3's behaviour): if this
    starts to pass, the library changed and the workaround may go."""
    from apscheduler.jobstores.base import JobLookupError

    scheduler, failures = _in_its_pass(monkeypatch, BackgroundScheduler)
    thread = scheduler._thread
    scheduler.shutdown(wait=False)
    assert not thread.is_alive()
    assert len(failures) == 1 and isinstance(failures[0], JobLookupError)


def test_a_scheduler_thread_that_died_is_replaced_and_the_tournament_ends(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch, caplog: pytest.LogCaptureFixture
) -> None:
    """The state file busy beyond SQLite's timeout while APScheduler removes a job it handed
    over: the error ends APScheduler's thread (it does not catch it there). The runner sees the
    thread gone, starts a new scheduler on the same state file, and every match is played and
    delivered once."""
    import logging

    from apscheduler.jobstores.sqlalchemy import SQLAlchemyJobStore
    from sqlalchemy.exc import OperationalError

    from tests.unit.schedule.test_schedule import COMPRESSED, FAKE, services_log, write_schedule
    from tournament import Ledger, ScheduledMatchState, run_schedule

    failures: list[BaseException | None] = []
    monkeypatch.setattr(threading, "excepthook", lambda args: failures.append(args.exc_value))
    real_remove = SQLAlchemyJobStore.remove_job
    busy = {"left": 1}

    def remove_job(store: SQLAlchemyJobStore, job_id: str) -> None:
        if job_id.startswith("pull:") and busy["left"]:
            busy["left"] -= 1
            raise OperationalError("DELETE FROM apscheduler_jobs", {}, Exception("locked"))
        real_remove(store, job_id)

    monkeypatch.setattr(SQLAlchemyJobStore, "remove_job", remove_job)
    path = write_schedule(tmp_path, COMPRESSED + "matches:\n  - {id: m1, red: alpha, "
                          "blue: bravo, stream_start: '+3.5s', stream_length_s: 0.2}\n")
    state = tmp_path / "state.sqlite"
    finished: list[int] = []
    with caplog.at_level(logging.ERROR, logger="tournament.runner"):
        runner = threading.Thread(target=lambda: finished.append(run_schedule(
            path, state, services=FAKE, exit_when_done=True, poll_s=0.1)))
        runner.start()
        runner.join(timeout=30)
        assert not runner.is_alive(), "the tournament stalled with its scheduler's thread gone"
    assert finished == [0]
    assert busy["left"] == 0 and len(failures) == 1
    assert isinstance(failures[0], OperationalError)
    assert any("the job scheduler's thread ended" in r.getMessage() for r in caplog.records)
    row = Ledger(state).row("m1")
    assert row.state is ScheduledMatchState.DELIVERED and row.attempts == 1
    steps = [what for what, match, _ in services_log(path) if match == "m1"]
    assert steps == ["pull", "play-start", "play-end", "deliver"]  # each step once
