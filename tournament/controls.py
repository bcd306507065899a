"""The operator's controls over a running tournament, acting on its state file.

* :func:`abort` asks the scheduler to stop a running match (SIGTERM, a grace period for the
  match to stop and collect its logs, then SIGKILL); the match becomes ABORTED with the reason.
* :func:`reschedule` plans a match again (un-cancel, or a new time): from the schedule's time,
  or a new one.
* :func:`apply_file` makes the edited schedule file the one the tournament runs. Until then the
  state file's recorded copy runs on, so that an edit (a half's length, a team file) never
  reaches the next match without the operator saying so.
* :func:`file_differences` lists where the file's times differ from the state's.
"""

from __future__ import annotations

import logging
from dataclasses import replace
from datetime import UTC, datetime
from pathlib import Path

from orchestrator import ConfigError, Problem, ScheduleError
from orchestrator.config import PlannedMatch, Schedule, load_schedule, resolve_time
from tournament.state import Ledger, OperatorRequest, ScheduledMatchState

log = logging.getLogger(__name__)
S = ScheduledMatchState

DEFAULT_ABORT_GRACE_S = 150.0
"""Seconds an aborted match has to stop and collect its logs (the league's 2 min of grace for
the robots, and the collection) before it is killed."""
RESCHEDULABLE = (S.CANCELLED, S.MISSED, S.FAILED, S.ABORTED, S.PLANNED, S.PULLED)


def recorded_schedule(ledger: Ledger) -> Schedule:
    """The schedule the tournament runs: the copy in the state file (the file as it was when
    the tournament started or the operator last applied it)."""
    path = ledger.get_meta("schedule")
    if path is None:
        raise ScheduleError(f"{ledger.path}: not a tournament state file (no schedule recorded)")
    return load_schedule(path, text=ledger.get_meta("schedule_text"))


def reference_of(ledger: Ledger) -> datetime:
    text = ledger.get_meta("reference")
    if text is None:
        raise ScheduleError(f"{ledger.path}: not a tournament state file (no reference time)")
    return datetime.fromisoformat(text)


def _times(planned: PlannedMatch) -> dict[str, str]:
    return {
        "pull_at": planned.pull_at.isoformat(),
        "play_at": planned.play_at.isoformat(),
        "stream_start": planned.stream_start.isoformat(),
        "stream_end": planned.stream_end.isoformat(),
        "deliver_at": planned.deliver_at.isoformat(),
    }


def abort(ledger: Ledger, match_id: str, *, reason: str,
          grace_s: float = DEFAULT_ABORT_GRACE_S) -> None:
    """Ask the scheduler that plays ``match_id`` to stop it."""
    state = _state(ledger, match_id)
    if state is not S.PLAYING:
        hint = " (use 'hlvs schedule cancel' for a match not yet played)" if state in (
            S.PLANNED, S.PULLING, S.PULLED) else ""
        raise ScheduleError(f"match {match_id} is {state.value}; only a PLAYING match can be "
                            f"aborted{hint}")
    if not reason.strip():
        raise ScheduleError("an abort needs a reason (--reason), recorded with the match")
    ledger.set_request(match_id, {"action": "abort", "reason": reason, "grace_s": grace_s,
                                  "at": datetime.now(UTC).isoformat()})


def reschedule(ledger: Ledger, match_id: str, *, at: str | None = None,
               now: datetime | None = None) -> PlannedMatch:
    """Plan ``match_id`` again: at ``at`` (ISO 8601, or ``+30m`` from now), or at the
    recorded schedule's time. Refuses a time already past."""
    now = now or datetime.now(UTC)
    state = _state(ledger, match_id)
    if state not in RESCHEDULABLE:
        raise ScheduleError(
            f"match {match_id} is {state.value}; only a match not played (or cancelled, missed, "
            "failed, aborted) can be rescheduled")
    schedule = recorded_schedule(ledger)
    try:
        match = schedule.match(match_id)
    except KeyError:
        raise ScheduleError(f"match {match_id} is not in the schedule any more") from None
    reference = reference_of(ledger)
    if at is not None:
        try:
            stream = resolve_time(at, now)
        except ValueError:
            raise ConfigError([Problem(
                "--at", "", f"{at!r} is not a time",
                expected="ISO 8601 with a time zone or an offset like +30m")]) from None
        match = replace(match, stream_start=stream.isoformat())
    planned = replace(schedule, matches=(match,)).plan(reference)[0]
    if planned.stream_start <= now:
        raise ScheduleError(
            f"match {match_id}: its stream time {planned.stream_start.isoformat()} has passed; "
            "give a new one with --at (e.g. --at +30m)")
    if planned.pull_at < now:  # the pull lead cannot be kept: pull now, play before the stream
        lead = (planned.stream_start - now) / 2
        planned = replace(planned, pull_at=now, play_at=now + min(
            lead, planned.play_at - planned.pull_at))
    why = "un-cancelled" if state is S.CANCELLED else f"rescheduled from {state.value}"
    ledger.reschedule(match_id, _times(planned),
                      note=f"{why}: stream {planned.stream_start.isoformat(timespec='seconds')}")
    return planned


def file_differences(ledger: Ledger) -> list[str]:
    """Sentences for each match whose time in the schedule file differs from the state's (the
    state's is the one kept), and for an edited file not yet applied."""
    path = ledger.get_meta("schedule")
    if path is None:
        return []
    notes = []
    try:
        text = Path(path).read_text(encoding="utf-8")
    except OSError as exc:
        return [f"{path}: cannot be read ({exc.strerror}); the recorded copy runs on"]
    if ledger.get_meta("schedule_text") not in (None, text):
        notes.append(f"{path} was edited; the tournament runs the recorded copy until "
                     f"'hlvs schedule apply --state {ledger.path}'")
    try:
        in_file = {p.match.id: p for p in load_schedule(path).plan(reference_of(ledger))}
    except ConfigError as exc:
        return [*notes, f"{path} is not valid now: {exc}"]
    for row in ledger.rows():
        planned = in_file.get(row.id)
        if planned is None:
            notes.append(f"match {row.id}: not in {path} any more")
        elif planned.stream_start != row.stream_start:
            notes.append(
                f"match {row.id}: the file says stream {_at(planned.stream_start)}, the "
                f"state keeps {_at(row.stream_start)} ({row.state.value}); "
                f"'hlvs schedule reschedule {row.id}' or 'hlvs schedule apply' to change it")
    return notes


def apply_file(ledger: Ledger, *, now: datetime | None = None) -> list[str]:
    """Make the schedule file the tournament's schedule: new matches are added, matches not yet
    started whose time the edit changed take the file's time (unless it has passed; a match
    rescheduled by hand keeps its time when the edit left it alone), matches no longer in the
    file and not started are cancelled.
    Refuses a file with errors (``hlvs check``). Returns what changed, one sentence each."""
    from orchestrator.config import check_schedule

    now = now or datetime.now(UTC)
    path = ledger.get_meta("schedule")
    if path is None:
        raise ScheduleError(f"{ledger.path}: not a tournament state file (no schedule recorded)")
    problems = check_schedule(path)
    if any(p.severity == "error" for p in problems):
        raise ConfigError(problems)
    text = Path(path).read_text(encoding="utf-8")
    schedule = load_schedule(path, text=text)
    changes = []
    rows = {row.id: row for row in ledger.rows()}
    reference = reference_of(ledger)
    planned_all = schedule.plan(reference)
    before = {p.match.id: p.stream_start for p in recorded_schedule(ledger).plan(reference)}
    for planned in planned_all:
        row = rows.get(planned.match.id)
        if row is None:
            ledger.ensure({"id": planned.match.id, "kind": planned.match.kind,
                           "red": str(planned.match.red), "blue": str(planned.match.blue),
                           **_times(planned)})
            changes.append(f"match {planned.match.id}: added")
        elif (row.state not in (S.PLANNED, S.PULLED) or planned.stream_start == row.stream_start
              or before.get(row.id) == planned.stream_start):
            continue  # the file did not move it: a time given by hand (reschedule) is kept
        elif planned.stream_start <= now:
            changes.append(
                f"match {row.id}: the file's stream {_at(planned.stream_start)} has passed; "
                f"it keeps {_at(row.stream_start)} ('hlvs schedule reschedule {row.id} --at "
                "TIME' to move it)")
        else:
            ledger.reschedule(row.id, _times(planned), note="times from the applied schedule")
            changes.append(f"match {row.id}: stream {_at(planned.stream_start)}")
    listed = {p.match.id for p in planned_all}
    for row in rows.values():
        if row.id not in listed and ledger.transition(
                row.id, (S.PLANNED, S.PULLED), S.CANCELLED,
                note="not in the applied schedule"):
            changes.append(f"match {row.id}: cancelled (not in the file any more)")
    if ledger.get_meta("schedule_text") != text:
        changes.append("settings (game defaults, teams, timing) apply from the next step of "
                       "each match")
    ledger.set_meta("schedule_text", text)
    ledger.set_meta("applied_at", now.isoformat())
    return changes


def _at(when: datetime) -> str:
    return when.isoformat(timespec="seconds")


def _state(ledger: Ledger, match_id: str) -> ScheduledMatchState:
    try:
        return ledger.row(match_id).state
    except KeyError:
        raise ScheduleError(f"no match {match_id!r} in {ledger.path}") from None


def abort_request(request: OperatorRequest | None) -> tuple[str, float] | None:
    """(reason, grace) of a recorded abort request."""
    if not request or request.get("action") != "abort":
        return None
    return str(request.get("reason", "")), float(request.get("grace_s", DEFAULT_ABORT_GRACE_S))
