"""The operator's controls: abort a running match, reschedule or un-cancel one, apply an edited
schedule only when asked; warnings when the file's times differ from the state's."""

from __future__ import annotations

import json
import threading
import time
from collections.abc import Iterator
from datetime import UTC, datetime, timedelta
from pathlib import Path

import pytest

from hlvs.cli import main
from orchestrator.config.schedule import load_schedule
from tests.unit.schedule import fake_services
from tests.unit.schedule.test_schedule import COMPRESSED, FAKE, services_log, write_schedule
from tournament import Ledger, ScheduledMatchState, init_state, run_schedule

S = ScheduledMatchState


@pytest.fixture
def slow_play() -> Iterator[None]:
    before = fake_services.PLAY_SECONDS
    fake_services.PLAY_SECONDS = 30.0
    yield
    fake_services.PLAY_SECONDS = before


def _wait_for(predicate: object, timeout: float = 30.0) -> None:
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if predicate():  # type: ignore[operator]
            return
        time.sleep(0.05)
    raise AssertionError("timed out")


def test_abort_a_running_match_then_play_it_again(
    tmp_path: Path, slow_play: None, capsys: pytest.CaptureFixture[str]
) -> None:
    path = write_schedule(
        tmp_path,
        COMPRESSED + "matches:\n  - {id: m1, red: alpha, blue: bravo, stream_start: '+3.5s',"
        " stream_length_s: 0.2}\n",
    )
    state = tmp_path / "state.sqlite"
    stop = threading.Event()
    thread = threading.Thread(target=run_schedule, args=(path, state), kwargs={
        "services": FAKE, "poll_s": 0.1, "stop": stop})
    thread.start()
    try:
        _wait_for(lambda: state.exists() and any(r.id == "m1" and r.state is S.PLAYING
                                                 for r in Ledger(state).rows()))
        ledger = Ledger(state)
        assert main(["schedule", "abort", "m1", "--state", str(state), "--reason",
                     "red's robot fell through the floor", "--grace", "5"]) == 0
        _wait_for(lambda: ledger.row("m1").state is S.ABORTED)
        row = ledger.row("m1")
        assert row.note == "aborted by the operator: red's robot fell through the floor"
        assert row.request is None and row.attempts == 1
        assert [w for w, _, _ in services_log(path)][-1] == "play-stopped"
        # a second abort is refused: the match is not running
        assert main(["schedule", "abort", "m1", "--state", str(state), "--reason", "x"]) == 1
        assert "only a PLAYING match can be aborted" in capsys.readouterr().err
        fake_services.PLAY_SECONDS = 0.2
        assert main(["schedule", "reschedule", "m1", "--state", str(state), "--at", "+2s"]) == 0
        assert ledger.row("m1").state is S.PLANNED
        _wait_for(lambda: ledger.row("m1").state is S.DELIVERED)
    finally:
        stop.set()
        thread.join(timeout=30)
    row = ledger.row("m1")
    assert row.attempts == 2 and row.result is not None and row.result["status"] == "success"
    states = [to for _, _, _, to, _ in ledger.history("m1")]
    assert states.count("PLAYING") == 2 and "ABORTED" in states
    out = capsys.readouterr().out
    assert "m1: PLANNED, pull" in out


def test_uncancel_and_file_time_warnings(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = write_schedule(
        tmp_path, "matches:\n  - {id: m1, red: alpha, blue: bravo, stream_start: '+2h'}\n"
        "  - {id: m2, red: charlie, blue: delta, stream_start: '+3h'}\n")
    state = tmp_path / "state.sqlite"
    init_state(path, state)
    ledger = Ledger(state)
    assert main(["schedule", "cancel", "m1", "--state", str(state)]) == 0
    assert main(["schedule", "reschedule", "m1", "--state", str(state)]) == 0
    row = ledger.row("m1")
    assert row.state is S.PLANNED and row.note.startswith("un-cancelled: stream ")
    planned = row.stream_start
    # the file's time changes: the state keeps its own and says so
    path.write_text(path.read_text().replace("'+3h'", "'+4h'"))
    capsys.readouterr()
    assert main(["schedule", "status", "--state", str(state)]) == 0
    err = capsys.readouterr().err
    assert "was edited" in err and "hlvs schedule apply" in err
    assert "match m2: the file says stream" in err and "the state keeps" in err
    assert ledger.row("m1").stream_start == planned
    new = (datetime.now(UTC) + timedelta(hours=5)).replace(microsecond=0)
    assert main(["schedule", "reschedule", "m1", "--state", str(state), "--at",
                 new.isoformat()]) == 0
    assert ledger.row("m1").stream_start == new
    assert main(["schedule", "reschedule", "m1", "--state", str(state), "--at", "soon"]) == 2
    assert "--at: 'soon' is not a time (expected ISO 8601" in capsys.readouterr().err


def test_an_edited_schedule_applies_only_when_the_operator_says_so(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    body = (COMPRESSED + "game_defaults: {seed: 1}\n"
            "matches:\n  - {id: m1, red: alpha, blue: bravo, stream_start: '+3.5s',"
            " stream_length_s: 0.2}\n")
    path = write_schedule(tmp_path, body)
    state = tmp_path / "state.sqlite"
    init_state(path, state, services=FAKE)
    ledger = Ledger(state)
    path.write_text(path.read_text().replace("seed: 1", "seed: 2")
                    + "  - {id: m2, red: charlie, blue: delta, stream_start: '+3.9s',"
                    " stream_length_s: 0.2}\n")
    assert run_schedule(path, state, services=FAKE, exit_when_done=True, poll_s=0.1) == 0
    assert json.loads((tmp_path / "out" / "m1" / "game_defaults.json").read_text()) == {
        "seed": 1}
    assert [r.id for r in ledger.rows()] == ["m1"]  # the new match waits for apply too
    assert main(["schedule", "apply", "--state", str(state)]) == 0
    out = capsys.readouterr().out
    assert "match m2: added" in out and "settings" in out
    assert main(["schedule", "status", "--state", str(state)]) == 0
    assert "was edited" not in capsys.readouterr().err
    row = ledger.row("m2")
    assert row.state is S.PLANNED


@pytest.mark.parametrize("ignores_sigterm", [False, True])
def test_an_aborted_match_process_gets_sigterm_then_sigkill_after_the_grace(
    tmp_path: Path, ignores_sigterm: bool
) -> None:
    """The local pool's wait: SIGTERM on the abort request (``hlvs match`` stops and collects),
    SIGKILL when the process is still there after the grace period."""
    import signal
    import subprocess
    import sys

    from tournament.services import Abort, MatchContext, _wait_or_abort

    code = ("import signal, time\n"
            + ("signal.signal(signal.SIGTERM, signal.SIG_IGN)\n" if ignores_sigterm else "")
            + "print('up', flush=True)\ntime.sleep(60)\n")
    proc = subprocess.Popen([sys.executable, "-c", code], stdout=subprocess.PIPE)
    assert proc.stdout is not None and proc.stdout.readline() == b"up\n"
    asked = time.monotonic() + 0.3
    schedule = load_schedule(write_schedule(
        tmp_path, "matches:\n  - {id: m1, red: alpha, blue: bravo, stream_start: '+1h'}\n"))
    ctx = MatchContext(
        schedule=schedule, planned=schedule.plan(datetime.now(UTC))[0],
        red=schedule.team("alpha"), blue=schedule.team("bravo"), out_dir=tmp_path / "m1",
        abort=lambda: Abort(reason="test", grace_s=0.5) if time.monotonic() > asked else None)
    started = time.monotonic()
    with proc.stdout:
        _wait_or_abort(ctx, proc)
    took = time.monotonic() - started
    expected = -signal.SIGKILL if ignores_sigterm else -signal.SIGTERM
    assert proc.returncode == expected
    assert took < 5.0 and (took >= 0.8 if ignores_sigterm else True)


def test_a_match_that_dies_with_a_stopping_scheduler_is_replayed_not_failed(
    tmp_path: Path,
) -> None:
    from tournament import jobs
    from tournament.runner import recover_interrupted

    path = write_schedule(
        tmp_path, COMPRESSED + "matches:\n  - {id: m1, red: alpha, blue: bravo,"
        " stream_start: '+1h'}\n")
    state = tmp_path / "state.sqlite"
    init_state(path, state, services=FAKE)
    ledger = Ledger(state)
    fake_services.BROKEN.add("m1")
    try:
        for stopping in (True, False):
            ledger.reschedule("m1", {"pull_at": datetime.now(UTC).isoformat(),
                                     "play_at": datetime.now(UTC).isoformat()}, note="now")
            if stopping:
                jobs.STOPPING.set()
            jobs.play_job(str(state), "m1")
            jobs.STOPPING.clear()
            if stopping:  # the scheduler's stop killed it: left PLAYING, put back at restart
                assert ledger.row("m1").state is S.PLAYING
                assert recover_interrupted(ledger) == ["m1"]
                assert ledger.row("m1").state is S.PULLED
            else:
                assert ledger.row("m1").state is S.FAILED
                assert ledger.row("m1").note == "infrastructure: report.json was not written"
    finally:
        fake_services.BROKEN.clear()


def test_apply_of_an_unrelated_edit_keeps_the_times_given_by_hand(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A half's length edited and applied: a match rescheduled by hand keeps its new time; a
    match whose time the edit changed takes it, unless the file's time has passed."""
    path = write_schedule(
        tmp_path, "game_defaults: {seed: 1}\n"
        "matches:\n  - {id: m1, red: alpha, blue: bravo, stream_start: '+2h'}\n"
        "  - {id: m2, red: charlie, blue: delta, stream_start: '+3h'}\n"
        "  - {id: m3, red: alpha, blue: charlie, stream_start: '+4h'}\n")
    state = tmp_path / "state.sqlite"
    init_state(path, state)
    ledger = Ledger(state)
    moved = (datetime.now(UTC) + timedelta(hours=6)).replace(microsecond=0)
    assert main(["schedule", "reschedule", "m1", "--state", str(state), "--at",
                 moved.isoformat()]) == 0
    m2, m3 = ledger.row("m2").stream_start, ledger.row("m3").stream_start
    past = (datetime.now(UTC) - timedelta(hours=1)).replace(microsecond=0).isoformat()
    path.write_text(path.read_text().replace("seed: 1", "seed: 2").replace("'+3h'", "'+5h'")
                    .replace("'+4h'", f"'{past}'"))
    capsys.readouterr()
    assert main(["schedule", "apply", "--state", str(state)]) == 0
    out = capsys.readouterr().out
    assert ledger.row("m1").stream_start == moved and "m1" not in out
    assert ledger.row("m2").stream_start == m2 + timedelta(hours=2)
    assert "match m2: stream" in out
    assert ledger.row("m3").stream_start == m3 and ledger.row("m3").state is S.PLANNED
    assert "match m3: the file's stream" in out and "has passed" in out


def test_list_with_a_state_prints_the_times_the_state_keeps(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = write_schedule(
        tmp_path, "matches:\n  - {id: m1, red: alpha, blue: bravo, stream_start: '+2h'}\n")
    state = tmp_path / "state.sqlite"
    init_state(path, state)
    moved = (datetime.now(UTC) + timedelta(hours=7)).replace(microsecond=0)
    assert main(["schedule", "reschedule", "m1", "--state", str(state), "--at",
                 moved.isoformat()]) == 0
    capsys.readouterr()
    assert main(["schedule", "list", str(path), "--state", str(state), "--json"]) == 0
    [row] = json.loads(capsys.readouterr().out)
    assert row["stream_start"] == moved.isoformat() and row["state"] == "PLANNED"
    assert main(["schedule", "list", str(path), "--state", str(state)]) == 0
    assert f"stream {moved.isoformat()} (PLANNED)" in capsys.readouterr().out


def test_status_watch_started_before_run_waits_for_the_state_file(tmp_path: Path) -> None:
    import os
    import signal
    import subprocess
    import sys

    path = write_schedule(
        tmp_path, "matches:\n  - {id: m1, red: alpha, blue: bravo, stream_start: '+2h'}\n")
    state = tmp_path / "state.sqlite"
    watch = subprocess.Popen(
        [sys.executable, "-m", "hlvs.cli", "schedule", "status", "--state", str(state),
         "--watch", "--every", "0.2"], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
        text=True, env={**os.environ, "PYTHONUNBUFFERED": "1"})
    try:
        assert watch.stdout is not None
        first = watch.stdout.readline()
        assert first.startswith(f"waiting for {state}"), first
        time.sleep(1.0)
        assert watch.poll() is None  # still waiting, not exited
        init_state(path, state)
        deadline = time.monotonic() + 30
        seen = ""
        while "m1" not in seen and time.monotonic() < deadline:
            seen += watch.stdout.readline()
        assert "m1" in seen and "PLANNED" in seen
    finally:
        watch.send_signal(signal.SIGINT)
        watch.wait(timeout=10)


def test_a_stop_before_the_shootout_leaves_the_knockout_match_to_be_replayed(
    tmp_path: Path,
) -> None:
    """SIGTERM just as a knockout match ended in a draw: no shoot-out is started and the match
    is not FAILED; it stays PLAYING, marked interrupted, for the next start."""
    from tournament import jobs
    from tournament.runner import recover_interrupted

    path = write_schedule(
        tmp_path, COMPRESSED + "matches:\n  - {id: k1, kind: knockout, red: alpha, blue: bravo,"
        " stream_start: '+1h'}\n")
    state = tmp_path / "state.sqlite"
    init_state(path, state, services=FAKE)
    ledger = Ledger(state)
    fake_services.DRAWN.add("k1")
    fake_services.STOP_AFTER_PLAY.add("k1")
    try:
        ledger.reschedule("k1", {"pull_at": datetime.now(UTC).isoformat(),
                                 "play_at": datetime.now(UTC).isoformat()}, note="now")
        jobs.play_job(str(state), "k1")
    finally:
        jobs.STOPPING.clear()
        fake_services.DRAWN.clear()
        fake_services.STOP_AFTER_PLAY.clear()
    row = ledger.row("k1")
    assert row.state is S.PLAYING and row.note.startswith("interrupted by the scheduler's stop")
    assert "shootout" not in [w for w, _, _ in services_log(path)]
    assert recover_interrupted(ledger) == ["k1"] and ledger.row("k1").state is S.PULLED
