"""The tournament ledger: one row per match in the SQLite state file, beside APScheduler's jobs.

The ledger is the truth about what happened; APScheduler only says when to look. Each job moves
its match through the states below with a compare-and-set update, so a job that fires twice (or
again after a restart) finds the match already past its step and does nothing:

    PLANNED -> PULLING -> PULLED -> PLAYING -> PLAYED -> DELIVERING -> DELIVERED
    DELIVERING -> LOGS_PENDING (a set failed; it stays in the log store and is retried)
    LOGS_PENDING -> DELIVERING (a retry) ... -> LOGS_FAILED (no attempt left; hlvs logs deliver)
    any non-final state -> MISSED (its window closed) | FAILED (a typed failure) | CANCELLED
    PLAYING -> ABORTED (the operator stopped it; hlvs schedule reschedule plays it again)
    CANCELLED | MISSED | FAILED | ABORTED -> PLANNED (hlvs schedule reschedule)

Every set of logs has its own state in the row's ``logs`` (see :mod:`tournament.logs`),
so "played" (PLAYED and after) and "logs delivered" (DELIVERED) are told apart.
"""

from __future__ import annotations

import json
import sqlite3
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from datetime import UTC, datetime
from enum import StrEnum
from pathlib import Path
from typing import Any, TypedDict

from tournament.logs import TeamLogs


class MatchResultRecord(TypedDict):
    """The ledger's result of a played or failed match (``tournament.PlayOutcome.as_dict``)."""

    status: str  # "success" or the failure class of report.json
    score: dict[str, int | None]  # {"red": goals, "blue": goals}
    winner: str | None  # "red" | "blue" | "draw" | None
    red_team: str
    blue_team: str
    winner_team: str | None
    cause: str
    out_dir: str  # the match's output folder
    shootout: dict[str, int] | None  # color -> goals in the penalty shoot-out


class OperatorRequest(TypedDict):
    """An operator's pending request that the match's running job acts on."""

    action: str  # "abort"
    reason: str
    grace_s: float
    at: str  # ISO time of the request


class ScheduledMatchState(StrEnum):
    PLANNED = "PLANNED"
    PULLING = "PULLING"
    PULLED = "PULLED"
    PLAYING = "PLAYING"
    PLAYED = "PLAYED"
    DELIVERING = "DELIVERING"
    DELIVERED = "DELIVERED"
    LOGS_PENDING = "LOGS_PENDING"  # played; a log set failed, a retry is due
    LOGS_FAILED = "LOGS_FAILED"  # played; a log set failed every attempt (hlvs logs deliver)
    MISSED = "MISSED"
    FAILED = "FAILED"
    CANCELLED = "CANCELLED"
    ABORTED = "ABORTED"  # stopped by the operator while playing

    @property
    def final(self) -> bool:
        return self in (
            ScheduledMatchState.DELIVERED,
            ScheduledMatchState.LOGS_FAILED,
            ScheduledMatchState.MISSED,
            ScheduledMatchState.FAILED,
            ScheduledMatchState.CANCELLED,
            ScheduledMatchState.ABORTED,
        )

    @property
    def played(self) -> bool:
        """The match was played to its end (its logs may still be on their way)."""
        return self in PLAYED_STATES


PLAYED_STATES = frozenset({
    ScheduledMatchState.PLAYED,
    ScheduledMatchState.DELIVERING,
    ScheduledMatchState.DELIVERED,
    ScheduledMatchState.LOGS_PENDING,
    ScheduledMatchState.LOGS_FAILED,
})


@dataclass(frozen=True, slots=True, kw_only=True)
class MatchRow:
    id: str
    state: ScheduledMatchState
    kind: str
    red: str  # team name, or "winner of X" until resolved
    blue: str
    pull_at: datetime
    play_at: datetime
    stream_start: datetime
    stream_end: datetime
    deliver_at: datetime
    attempts: int
    note: str
    result: MatchResultRecord | None
    updated_at: datetime
    not_before: datetime | None = None  # a deferred step waits until then
    logs: tuple[TeamLogs, ...] = ()
    request: OperatorRequest | None = None  # an operator's pending request (abort)

    def as_dict(self) -> dict[str, Any]:
        return {
            "id": self.id,
            "state": self.state.value,
            "kind": self.kind,
            "red": self.red,
            "blue": self.blue,
            "pull_at": self.pull_at.isoformat(),
            "play_at": self.play_at.isoformat(),
            "stream_start": self.stream_start.isoformat(),
            "stream_end": self.stream_end.isoformat(),
            "deliver_at": self.deliver_at.isoformat(),
            "attempts": self.attempts,
            "note": self.note,
            "result": self.result,
            "played": self.state.played,
            "logs_delivered": self.state is ScheduledMatchState.DELIVERED,
            "logs": [entry.as_dict() for entry in self.logs],
            "request": self.request,
        }


_SCHEMA = """
CREATE TABLE IF NOT EXISTS hlvs_meta (key TEXT PRIMARY KEY, value TEXT NOT NULL);
CREATE TABLE IF NOT EXISTS hlvs_matches (
    id TEXT PRIMARY KEY, state TEXT NOT NULL, kind TEXT NOT NULL, red TEXT NOT NULL,
    blue TEXT NOT NULL, pull_at TEXT NOT NULL, play_at TEXT NOT NULL, stream_start TEXT NOT NULL,
    stream_end TEXT NOT NULL, deliver_at TEXT NOT NULL, attempts INTEGER NOT NULL DEFAULT 0,
    note TEXT NOT NULL DEFAULT '', result TEXT, updated_at TEXT NOT NULL,
    not_before TEXT, logs TEXT, request TEXT);
CREATE TABLE IF NOT EXISTS hlvs_history (
    at TEXT NOT NULL, match_id TEXT NOT NULL, from_state TEXT, to_state TEXT NOT NULL,
    note TEXT NOT NULL DEFAULT '');
"""


def _now() -> str:
    return datetime.now(UTC).isoformat()


class Ledger:
    """Access to the match table; every method opens a short transaction (threads share it)."""

    def __init__(self, path: Path) -> None:
        self.path = Path(path)
        db = sqlite3.connect(self.path, timeout=30.0)
        try:
            db.execute("PRAGMA journal_mode=WAL")
            db.executescript(_SCHEMA)
            columns = {r[1] for r in db.execute("PRAGMA table_info(hlvs_matches)")}
            for column in ("logs", "request"):  # state files of earlier versions
                if column not in columns:
                    db.execute(f"ALTER TABLE hlvs_matches ADD COLUMN {column} TEXT")
        finally:
            db.close()

    @contextmanager
    def _connect(self) -> Iterator[sqlite3.Connection]:
        db = sqlite3.connect(self.path, timeout=30.0, isolation_level=None)
        try:
            db.execute("BEGIN IMMEDIATE")
            yield db
            db.execute("COMMIT")
        except BaseException:
            if db.in_transaction:
                db.execute("ROLLBACK")
            raise
        finally:
            db.close()

    def get_meta(self, key: str) -> str | None:
        with self._connect() as db:
            row = db.execute("SELECT value FROM hlvs_meta WHERE key=?", (key,)).fetchone()
        return None if row is None else str(row[0])

    def set_meta(self, key: str, value: str) -> None:
        with self._connect() as db:
            db.execute("INSERT OR REPLACE INTO hlvs_meta(key, value) VALUES (?, ?)", (key, value))

    def ensure(self, row: dict[str, Any]) -> bool:
        """Add a planned match unless it is already in the ledger; True when added."""
        with self._connect() as db:
            cur = db.execute(
                "INSERT OR IGNORE INTO hlvs_matches(id, state, kind, red, blue, pull_at, play_at,"
                " stream_start, stream_end, deliver_at, updated_at)"
                " VALUES (?, 'PLANNED', ?, ?, ?, ?, ?, ?, ?, ?, ?)",
                (
                    row["id"],
                    row["kind"],
                    row["red"],
                    row["blue"],
                    row["pull_at"],
                    row["play_at"],
                    row["stream_start"],
                    row["stream_end"],
                    row["deliver_at"],
                    _now(),
                ),
            )
            return cur.rowcount == 1

    def transition(
        self,
        match_id: str,
        allowed_from: tuple[ScheduledMatchState, ...],
        to: ScheduledMatchState,
        *,
        note: str = "",
        result: MatchResultRecord | None = None,
        count_attempt: bool = False,
        teams: tuple[str, str] | None = None,
    ) -> bool:
        """Compare-and-set: move the match to ``to`` only if it is in ``allowed_from``."""
        with self._connect() as db:
            row = db.execute("SELECT state FROM hlvs_matches WHERE id=?", (match_id,)).fetchone()
            if row is None or ScheduledMatchState(row[0]) not in allowed_from:
                return False
            sets = ["state=?", "note=?", "updated_at=?"]
            args: list[Any] = [to.value, note, _now()]
            if result is not None:
                sets.append("result=?")
                args.append(json.dumps(result, sort_keys=True))
            if count_attempt:
                sets.append("attempts=attempts+1")
            if teams is not None:
                sets += ["red=?", "blue=?"]
                args += list(teams)
            db.execute(f"UPDATE hlvs_matches SET {', '.join(sets)} WHERE id=?", (*args, match_id))
            db.execute(
                "INSERT INTO hlvs_history(at, match_id, from_state, to_state, note)"
                " VALUES (?, ?, ?, ?, ?)",
                (_now(), match_id, row[0], to.value, note),
            )
            return True

    def defer(self, match_id: str, until: datetime, note: str) -> None:
        """The next step of the match waits until ``until`` (e.g. teams of a knockout slot)."""
        with self._connect() as db:
            db.execute(
                "UPDATE hlvs_matches SET not_before=?, note=?, updated_at=? WHERE id=?",
                (until.isoformat(), note, _now(), match_id),
            )

    def set_logs(self, match_id: str, logs: list[TeamLogs]) -> None:
        with self._connect() as db:
            db.execute(
                "UPDATE hlvs_matches SET logs=?, updated_at=? WHERE id=?",
                (json.dumps([e.as_dict() for e in logs]), _now(), match_id),
            )

    def set_request(self, match_id: str, request: OperatorRequest | None) -> None:
        """Record (or clear) an operator's request that the running job acts on."""
        with self._connect() as db:
            db.execute(
                "UPDATE hlvs_matches SET request=? WHERE id=?",
                (json.dumps(request) if request is not None else None, match_id),
            )

    def reschedule(self, match_id: str, times: dict[str, str], note: str) -> None:
        """New times for a match (PLANNED again, not deferred)."""
        with self._connect() as db:
            row = db.execute("SELECT state FROM hlvs_matches WHERE id=?", (match_id,)).fetchone()
            sets = ", ".join(f"{k}=?" for k in times)
            db.execute(
                f"UPDATE hlvs_matches SET {sets}, state='PLANNED', not_before=NULL, note=?,"
                " request=NULL, updated_at=? WHERE id=?",
                (*times.values(), note, _now(), match_id),
            )
            db.execute(
                "INSERT INTO hlvs_history(at, match_id, from_state, to_state, note)"
                " VALUES (?, ?, ?, 'PLANNED', ?)",
                (_now(), match_id, row[0] if row else None, note),
            )

    def rows(self) -> list[MatchRow]:
        with self._connect() as db:
            rows = db.execute(
                "SELECT id, state, kind, red, blue, pull_at, play_at, stream_start, stream_end,"
                " deliver_at, attempts, note, result, updated_at, not_before, logs, request"
                " FROM hlvs_matches"
                " ORDER BY stream_start, id"
            ).fetchall()
        return [_row(r) for r in rows]

    def row(self, match_id: str) -> MatchRow:
        for row in self.rows():
            if row.id == match_id:
                return row
        raise KeyError(match_id)

    def history(self, match_id: str | None = None) -> list[tuple[str, str, str | None, str, str]]:
        with self._connect() as db:
            if match_id is None:
                return list(db.execute("SELECT * FROM hlvs_history ORDER BY rowid").fetchall())
            return list(
                db.execute(
                    "SELECT * FROM hlvs_history WHERE match_id=? ORDER BY rowid", (match_id,)
                ).fetchall()
            )


def _row(r: tuple[Any, ...]) -> MatchRow:
    ts = datetime.fromisoformat
    return MatchRow(
        id=r[0],
        state=ScheduledMatchState(r[1]),
        kind=r[2],
        red=r[3],
        blue=r[4],
        pull_at=ts(r[5]),
        play_at=ts(r[6]),
        stream_start=ts(r[7]),
        stream_end=ts(r[8]),
        deliver_at=ts(r[9]),
        attempts=int(r[10]),
        note=r[11],
        result=json.loads(r[12]) if r[12] else None,
        updated_at=ts(r[13]),
        not_before=ts(r[14]) if r[14] else None,
        logs=tuple(TeamLogs.from_dict(d) for d in json.loads(r[15])) if r[15] else (),
        request=json.loads(r[16]) if r[16] else None,
    )
