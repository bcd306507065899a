"""The operator's notifications and the scheduler's heartbeat.

``hlvs schedule run`` writes a heartbeat into the state file every few seconds (``heartbeat``,
and ``stopped_at`` when it stops); :func:`scheduler_state` tells from it whether a scheduler
runs, so that ``hlvs schedule status`` and the operator's page say "scheduler not running since
..." instead of showing a PLAYING match that nobody plays.

The notices (:data:`EVENTS`) go to the operators by mail and by signed webhooks (the same
signature as the service's, :mod:`contracts.webhooks`): a match FAILED, MISSED or LOGS_FAILED,
a match still pulled or played when its stream starts (``match.over_window``), and a scheduler that
stopped beating (``scheduler.stopped``, sent by ``hlvs schedule status --watch``: a dead
scheduler cannot tell). Each notice is written once into an outbox table of the state file and
sent, with retries, by whichever process holds the notification settings, so a restart loses
none and sends none twice.
"""

from __future__ import annotations

import hashlib
import json
import logging
import smtplib
import sqlite3
import urllib.error
import urllib.request
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass, field
from datetime import UTC, datetime, timedelta
from email.message import EmailMessage
from pathlib import Path
from typing import Any

from contracts import webhooks
from tournament.state import Ledger, MatchRow, ScheduledMatchState

log = logging.getLogger(__name__)
S = ScheduledMatchState

HEARTBEAT_S = 5.0
"""How often the scheduler writes its heartbeat."""
STALE_S = 60.0
"""A heartbeat older than this: the scheduler is not running."""
RETRY_S = (30.0, 120.0, 600.0, 1800.0)  # waits between attempts; then one every 30 min
GIVE_UP_AFTER = 20
EVENTS = ("match.failed", "match.missed", "match.logs_failed", "match.over_window",
          "scheduler.stopped")
_BY_STATE = {S.FAILED: "match.failed", S.MISSED: "match.missed",
             S.LOGS_FAILED: "match.logs_failed"}

_SCHEMA = """
CREATE TABLE IF NOT EXISTS hlvs_notices (
    key TEXT PRIMARY KEY, event TEXT NOT NULL, payload TEXT NOT NULL, created_at TEXT NOT NULL,
    channel TEXT NOT NULL, target TEXT NOT NULL, attempts INTEGER NOT NULL DEFAULT 0,
    next_attempt_at TEXT NOT NULL, sent_at TEXT, last_error TEXT);
"""


def _now() -> datetime:
    return datetime.now(UTC)


# --- heartbeat ---------------------------------------------------------------------------


def beat(ledger: Ledger, *, now: datetime | None = None) -> None:
    ledger.set_meta("heartbeat", (now or _now()).isoformat())
    ledger.set_meta("stopped_at", "")


def stopped(ledger: Ledger, *, now: datetime | None = None) -> None:
    """The scheduler stops (a clean stop: the match steps in progress ended or were left)."""
    ledger.set_meta("stopped_at", (now or _now()).isoformat())


@dataclass(frozen=True, slots=True)
class SchedulerState:
    running: bool
    since: datetime | None  # the last heartbeat (or the clean stop) of a scheduler not running
    text: str  # "" while it runs
    waiting: int = 0  # matches not final (that a scheduler not running leaves waiting)

    def as_dict(self) -> dict[str, Any]:
        return {"running": self.running,
                "since": self.since.isoformat(timespec="seconds") if self.since else None,
                "text": self.text, "waiting": self.waiting}


def scheduler_state(ledger: Ledger, *, now: datetime | None = None) -> SchedulerState:
    """Whether a scheduler runs this state file, from its heartbeat."""
    now = now or _now()
    heartbeat = ledger.get_meta("heartbeat")
    stop = ledger.get_meta("stopped_at")
    if stop:
        since = datetime.fromisoformat(stop)
        why = "stopped"
    elif heartbeat:
        since = datetime.fromisoformat(heartbeat)
        if (now - since).total_seconds() <= STALE_S:
            return SchedulerState(True, None, "")
        why = "its last heartbeat"
    else:
        return SchedulerState(False, None, "scheduler not running (never started on this "
                              "state file): hlvs schedule run")
    unfinished = [r.id for r in ledger.rows() if not r.state.final]
    at = since.isoformat(timespec="seconds")
    if not unfinished:
        return SchedulerState(False, since, f"scheduler stopped at {at}; every match is final")
    return SchedulerState(
        False, since, f"scheduler not running since {at} ({why}); {len(unfinished)} "
        "match(es) not final wait for it: hlvs schedule run", len(unfinished))


# --- settings ----------------------------------------------------------------------------


@dataclass(frozen=True, slots=True, kw_only=True)
class Webhook:
    url: str
    secret: str = field(repr=False)


@dataclass(frozen=True, slots=True, kw_only=True)
class NotifySettings:
    """Where the operators' notices go (``hlvs schedule run --notify-mail ... --notify-webhook
    ...``; recorded in the state file, secrets excepted: they are read from their files)."""

    mail_to: tuple[str, ...] = ()
    smtp_host: str = "localhost"
    smtp_port: int = 25
    mail_from: str = "hlvs@localhost"
    webhooks: tuple[Webhook, ...] = ()

    @property
    def any(self) -> bool:
        return bool(self.mail_to or self.webhooks)

    def recorded(self, secret_file: Path | None) -> str:
        return json.dumps({"mail_to": list(self.mail_to), "smtp_host": self.smtp_host,
                           "smtp_port": self.smtp_port, "mail_from": self.mail_from,
                           "webhooks": [w.url for w in self.webhooks],
                           "secret_file": str(secret_file) if secret_file else None})


def recorded_settings(ledger: Ledger) -> NotifySettings:
    """The settings ``hlvs schedule run`` recorded (none: no notices are sent)."""
    text = ledger.get_meta("notify")
    if not text:
        return NotifySettings()
    data = json.loads(text)
    secret = ""
    if data.get("secret_file"):
        try:
            secret = Path(data["secret_file"]).read_text(encoding="utf-8").strip()
        except OSError as exc:
            log.warning("webhook secret %s cannot be read (%s): webhooks are not signed",
                        data["secret_file"], exc.strerror)
    return NotifySettings(mail_to=tuple(data.get("mail_to", ())),
                          smtp_host=str(data.get("smtp_host", "localhost")),
                          smtp_port=int(data.get("smtp_port", 25)),
                          mail_from=str(data.get("mail_from", "hlvs@localhost")),
                          webhooks=tuple(Webhook(url=u, secret=secret)
                                         for u in data.get("webhooks", ())))


# --- outbox ------------------------------------------------------------------------------


class Outbox:
    """The notices of one state file: each written once (its key), sent with retries."""

    def __init__(self, ledger: Ledger, settings: NotifySettings) -> None:
        self.ledger = ledger
        self.settings = settings
        with self._db() as db:
            db.executescript(_SCHEMA)
        self.name = _name(ledger)

    @contextmanager
    def _db(self) -> Iterator[sqlite3.Connection]:
        db = sqlite3.connect(self.ledger.path, timeout=30.0)
        try:
            with db:  # one transaction
                yield db
        finally:
            db.close()

    def add(self, key: str, event: str, payload: dict[str, Any]) -> bool:
        """Queue a notice for every channel; False when it was queued before."""
        targets = [("mail", to) for to in self.settings.mail_to]
        targets += [("webhook", hook.url) for hook in self.settings.webhooks]
        if not targets:
            return False
        added = False
        body = json.dumps({"event": event, **payload}, sort_keys=True)
        at = _now().isoformat()
        with self._db() as db:
            for channel, target in targets:
                cur = db.execute(
                    "INSERT OR IGNORE INTO hlvs_notices(key, event, payload, created_at, channel,"
                    " target, next_attempt_at) VALUES (?, ?, ?, ?, ?, ?, ?)",
                    (f"{key}|{channel}|{target}", event, body, at, channel, target, at))
                added |= cur.rowcount == 1
        if added:
            log.info("notice %s queued (%s)", event, key)
        return added

    def scan(self, *, now: datetime | None = None,
             scheduler: SchedulerState | None = None) -> int:
        """Queue the notices the ledger calls for; returns how many were new."""
        now = now or _now()
        name = self.name
        new = 0
        for row in self.ledger.rows():
            event = _BY_STATE.get(row.state)
            if event is not None:
                new += self.add(f"{event}|{row.id}|{row.updated_at.isoformat()}", event,
                                _match_payload(name, row))
            elif row.state in (S.PULLING, S.PLAYING) and now >= row.stream_start:
                new += self.add(f"match.over_window|{row.id}|{row.stream_start.isoformat()}",
                                "match.over_window", _match_payload(name, row))
        if scheduler is not None and scheduler.waiting and scheduler.since is not None:
            new += self.add(f"scheduler.stopped|{scheduler.since.isoformat()}",
                            "scheduler.stopped", {"tournament": name, "text": scheduler.text,
                                                  "since": scheduler.since.isoformat()})
        return new

    def send_due(self, *, now: datetime | None = None,
                 mailer: Callable[[NotifySettings, str, str, dict[str, Any]], None] | None = None,
                 poster: Callable[[str, bytes, dict[str, str]], int] | None = None) -> int:
        """Send every due notice once; returns how many were sent."""
        now = now or _now()
        mailer = mailer or send_mail
        poster = poster or post
        with self._db() as db:
            due = db.execute(
                "SELECT key, event, payload, channel, target, attempts FROM hlvs_notices"
                " WHERE sent_at IS NULL AND attempts < ? AND next_attempt_at <= ?"
                " ORDER BY created_at", (GIVE_UP_AFTER, now.isoformat())).fetchall()
        secrets = {hook.url: hook.secret for hook in self.settings.webhooks}
        sent = 0
        for key, event, body, channel, target, attempts in due:
            error = None
            try:
                if channel == "mail":
                    mailer(self.settings, target, event, json.loads(body))
                else:
                    delivery = hashlib.sha256(key.encode()).hexdigest()[:32]  # same each retry
                    headers = webhooks.sign(secrets.get(target, ""), event=event,
                                            body=body.encode(), delivery_id=delivery)
                    status = poster(target, body.encode(), headers)
                    if status >= 300:
                        raise ValueError(f"HTTP {status} from {target}")
            except (OSError, ValueError, smtplib.SMTPException) as exc:
                error = f"{type(exc).__name__}: {exc}"
                log.warning("notice %s to %s failed (attempt %d): %s", event, target,
                            attempts + 1, error)
            wait = RETRY_S[min(attempts, len(RETRY_S) - 1)]
            with self._db() as db:
                db.execute(
                    "UPDATE hlvs_notices SET attempts=attempts+1, sent_at=?, last_error=?,"
                    " next_attempt_at=? WHERE key=?",
                    (None if error else _now().isoformat(), error,
                     (now + timedelta(seconds=wait)).isoformat(), key))
            if error is None:
                log.info("notice %s sent to %s", event, target)
                sent += 1
        return sent

    def notices(self) -> list[dict[str, Any]]:
        with self._db() as db:
            rows = db.execute("SELECT key, event, channel, target, attempts, sent_at, last_error"
                              " FROM hlvs_notices ORDER BY created_at, key").fetchall()
        return [dict(zip(("key", "event", "channel", "target", "attempts", "sent_at",
                          "last_error"), r, strict=True)) for r in rows]


def _name(ledger: Ledger) -> str:
    from orchestrator import ConfigError, ScheduleError
    from tournament.controls import recorded_schedule

    try:
        return recorded_schedule(ledger).name
    except (ConfigError, ScheduleError):
        return ""


def _match_payload(name: str, row: MatchRow) -> dict[str, Any]:
    return {"tournament": name, "match": {
        "id": row.id, "state": row.state.value, "red": row.red, "blue": row.blue,
        "stream_start": row.stream_start.isoformat(timespec="seconds"), "note": row.note,
        "logs": [e.describe() for e in row.logs]}}


_SUBJECT = {
    "match.failed": "match {id} FAILED",
    "match.missed": "match {id} MISSED",
    "match.logs_failed": "match {id}: logs not delivered (LOGS_FAILED)",
    "match.over_window": "match {id} not played when its stream started",
    "scheduler.stopped": "the scheduler is not running",
}
_ACTION = {
    "match.failed": "hlvs schedule reschedule {id} --state STATE [--at TIME]",
    "match.missed": "hlvs schedule reschedule {id} --state STATE --at TIME",
    "match.logs_failed": "fix the team's log target, then hlvs logs deliver; hlvs schedule "
                         "status shows the match DELIVERED",
    "match.over_window": "hlvs schedule status --state STATE (is the scheduler running? is "
                         "the simulator slot held by a longer match?)",
    "scheduler.stopped": "start it again: hlvs schedule run SCHEDULE --state STATE (a match "
                         "left PLAYING is played again)",
}


def message_text(event: str, data: dict[str, Any]) -> tuple[str, str]:
    """The subject and body of a notice's mail."""
    match = data.get("match") or {}
    ident = match.get("id", "")
    subject = f"[hlvs] {data.get('tournament', '')}: " + _SUBJECT[event].format(id=ident)
    lines = []
    if match:
        lines += [f"match:   {ident} ({match['red']} v {match['blue']})",
                  f"state:   {match['state']}", f"stream:  {match['stream_start']}"]
        if match.get("note"):
            lines.append(f"note:    {match['note']}")
        lines += [f"logs:    {entry}" for entry in match.get("logs", ())]
    else:
        lines.append(str(data.get("text", "")))
    lines += ["", "what to do: " + _ACTION[event].format(id=ident)]
    return subject, "\n".join(lines) + "\n"


def send_mail(settings: NotifySettings, to: str, event: str, data: dict[str, Any]) -> None:
    subject, body = message_text(event, data)
    message = EmailMessage()
    message["From"] = settings.mail_from
    message["To"] = to
    message["Subject"] = subject
    message.set_content(body)
    with smtplib.SMTP(settings.smtp_host, settings.smtp_port, timeout=10) as smtp:
        smtp.send_message(message)


def post(url: str, body: bytes, headers: dict[str, str]) -> int:
    """POST a signed notice; the HTTP status (an operator's own URL: no address check)."""
    request = urllib.request.Request(url, data=body, headers=headers, method="POST")
    try:
        with urllib.request.urlopen(request, timeout=10) as answer:  # noqa: S310 - http(s) only
            return int(answer.status)
    except urllib.error.HTTPError as exc:
        return int(exc.code)
