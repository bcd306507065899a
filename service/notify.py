"""Notifications: an outbox of mails and webhooks, written with each state change and sent by
the :class:`Notifier` thread with retries (so a restart loses none).

Webhooks are signed (see :mod:`service.webhooks`); mail goes through the SMTP server of the
settings (none configured: no mail rows are written).

A friendly the ladder scheduled (:class:`service.db.ladder.LadderFixture`) is told to both
teams, each from its own side (``side``: the submitting team plays red, the opponent blue), and
says that the ladder scheduled it (``ladder``) and against whom.
"""

from __future__ import annotations

import json
import logging
import secrets
import smtplib
import threading
from datetime import timedelta
from email.message import EmailMessage
from typing import TYPE_CHECKING, NotRequired, TypedDict

import httpx
from sqlalchemy import select
from sqlalchemy.orm import Session

from service import outbound, webhooks
from service.db import Notification, Submission, Team, now, transaction, utc
from service.db.ladder import LadderFixture
from service.matchfiles import OWN_COLOR
from service.results import MatchSummary
from service.settings import Settings

if TYPE_CHECKING:
    from sqlalchemy.orm import Session, sessionmaker

    from service.sealing import Sealer

log = logging.getLogger(__name__)

MAIL_EVENTS = {"submission.started", "submission.finished", "submission.failed"}


class NoticeLinks(TypedDict):
    """The API's links; the opponent of a ladder friendly gets only ``logs`` (its own)."""

    status: NotRequired[str]
    report: NotRequired[str]
    results: NotRequired[str]
    logs: str


class NoticePages(TypedDict):
    submissions: str
    live: str
    replay: str
    ladder: str


class SubmissionNotice(TypedDict):
    id: str
    state: str
    opponent: str  # the other team, as the notified team sees it
    side: str  # the notified team's colour: red (the submitting team) or blue (the opponent)
    ladder: bool  # a friendly the ladder scheduled (not charged)
    match_id: str | None
    failure_class: str | None
    failure_side: str | None
    cause: str | None
    charged: bool
    score: dict[str, int] | None
    outcome: str
    playing_s: float | None
    halves_playing: list[int] | None
    links: NoticeLinks
    pages: NoticePages


class NotificationPayload(TypedDict):
    """The data of a mail or webhook (stored as JSON in the outbox)."""

    event: str
    submission: SubmissionNotice


def outcome_of(row: Submission, results: MatchSummary | None, side: str = OWN_COLOR) -> str:
    """The outcome in words for the team playing ``side`` (the submitting team plays red): won,
    drew, lost, or why not played."""
    if row.state == "cancelled":
        return "cancelled"
    if row.state == "failed" and side != OWN_COLOR:
        where = " on the league's side" if row.failure_side == "league" else ""
        return f"not counted: {row.failure_class}{where}"
    if row.state == "failed":
        side = "the league's side (not charged)" if row.failure_side == "league" else \
            "your team's side"
        return f"not counted: {row.failure_class} on {side}"
    winner = results.winner if results is not None else None
    if row.state != "done" or winner is None:
        return row.state
    return {side: "won", "draw": "draw"}.get(winner, "lost")


def payload(row: Submission, event: str, settings: Settings,
            results: MatchSummary | None = None, *, side: str = OWN_COLOR,
            opponent: str | None = None, ladder: bool = False) -> NotificationPayload:
    """The notification's data: the submission, its score and outcome (from ``results``, the
    match's result as the database keeps it, when it ended), links to the API and to the pages
    a browser opens.
    ``side`` is the notified team's colour and ``opponent`` the other team (by default the
    submission's opponent); the blue side is not told the submitting team's own details."""
    public = settings.public_url.rstrip("/")
    base = f"{public}/v1/submissions/{row.id}"
    own = side == OWN_COLOR
    links: NoticeLinks = {"status": base, "report": base + "/report",
                          "results": base + "/results", "logs": base + "/logs"} if own else \
        {"logs": base + "/logs"}
    return {
        "event": event,
        "submission": {
            "id": row.id, "state": row.state, "opponent": opponent or row.opponent,
            "side": side, "ladder": ladder, "match_id": row.match_id,
            "failure_class": row.failure_class, "failure_side": row.failure_side,
            "cause": row.cause if own or row.failure_side == "league" else None,
            "charged": row.charged if own else False,
            "score": results.score if results is not None else None,
            "outcome": outcome_of(row, results, side),
            "playing_s": results.playing_s if results is not None else None,
            "halves_playing": list(results.halves_playing)
            if results is not None and results.halves_playing is not None else None,
            "links": links,
            "pages": {"submissions": f"{public}/watch/submissions",
                      "live": f"{public}/watch/live/{row.id}",
                      "replay": f"{public}/watch/replay/{row.id}",
                      "ladder": f"{public}/watch/ladder"},
        },
    }


def enqueue(session: Session, row: Submission, event: str, settings: Settings,
            results: MatchSummary | None = None) -> None:
    """Outbox rows for ``event``: a mail when the team has an address and SMTP is set, a
    webhook when the team has a webhook URL; for a friendly the ladder scheduled, to both
    teams, each from its side."""
    team = session.get(Team, row.team_id)
    if team is None:
        return
    fixture = session.get(LadderFixture, row.id)
    _enqueue_to(session, team, row, event, settings,
                payload(row, event, settings, results, ladder=fixture is not None))
    if fixture is None:
        return
    other = session.scalar(select(Team).where(Team.name == fixture.blue_team))
    if other is not None and other.id != team.id:
        _enqueue_to(session, other, row, event, settings,
                    payload(row, event, settings, results, side="blue", opponent=team.name,
                            ladder=True))


def _enqueue_to(session: Session, team: Team, row: Submission, event: str, settings: Settings,
                data: NotificationPayload) -> None:
    body = json.dumps(data, sort_keys=True)
    channels = []
    if team.email and settings.smtp_host and event in MAIL_EVENTS:
        channels.append("mail")
    if team.webhook_url:
        channels.append("webhook")
    for channel in channels:
        session.add(Notification(delivery_id=secrets.token_hex(16), team_id=team.id,
                                 submission_id=row.id, channel=channel, event=event,
                                 payload_json=body, attempts=0, next_attempt_at=now(),
                                 given_up=False))


def send_mail(settings: Settings, *, to: str, event: str, data: NotificationPayload) -> None:
    sub = data["submission"]
    message = EmailMessage()
    message["From"] = settings.mail_from
    message["To"] = to
    what = event.split(".", 1)[1]
    side = sub.get("side") or OWN_COLOR
    other = "blue" if side == "red" else "red"
    pages = sub.get("pages") or {}
    if sub.get("ladder"):
        message["Subject"] = f"[hlvs] ladder friendly {sub['id']} against {sub['opponent']} " \
            f"{what}"
        lines = [f"The ladder scheduled a friendly {sub['id']} of your team ({side}) against "
                 f"{sub['opponent']}; it {what}. It is not charged to your team.", ""]
    else:
        message["Subject"] = f"[hlvs] test match {sub['id']} {what}"
        lines = [f"Your test match {sub['id']} against {sub['opponent']} {what}.", ""]
    lines.append(f"state:   {sub['state']}")
    score = sub.get("score")
    if score:
        lines.append(f"score:   you ({side}) {score[side]} : {score[other]} {sub['opponent']}")
    if event != "submission.started":
        lines.append(f"outcome: {sub.get('outcome') or sub['state']}")
    if sub.get("playing_s") is not None:
        lines.append(f"played:  {sub['playing_s']:g} s in PLAYING, halves "
                     f"{sub.get('halves_playing') or 'none'}")
    if sub.get("cause"):
        lines.append(f"cause:   {sub['cause']}")
    lines += ["", "Open in a browser (sign in with your team token once):"]
    if event == "submission.started":
        lines.append(f"  watch live:   {pages.get('live', '')}")
    else:
        lines.append(f"  replay:       {pages.get('replay', '')}")
    lines += [f"  your matches: {pages.get('submissions', '')}",
              f"  ladder:       {pages.get('ladder', '')}",
              "", "For scripts (API, Authorization: Bearer <token>):"]
    if "results" in sub["links"]:
        lines.append(f"  results: {sub['links']['results']}")
    lines.append(f"  logs:    {sub['links']['logs']}" + (
        "  (your team's robots' logs)" if side != OWN_COLOR else ""))
    message.set_content("\n".join(lines) + "\n")
    with smtplib.SMTP(settings.smtp_host, settings.smtp_port, timeout=10) as smtp:
        smtp.send_message(message)


class Notifier:
    """Sends due outbox rows; failures are retried with exponential back-off."""

    def __init__(
        self, *, settings: Settings, sessions: sessionmaker[Session], sealer: Sealer
    ) -> None:
        self.settings = settings
        self._sessions = sessions
        self._sealer = sealer
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None
        # no proxy from the environment and no redirect: a delivery goes to the address that
        # service.outbound checked, and nowhere else
        self._http = httpx.Client(timeout=self.settings.webhook_timeout_s, trust_env=False,
                                  follow_redirects=False)
        self._allowed = outbound.allowed_networks(self.settings)

    def start(self) -> None:
        self._thread = threading.Thread(target=self._run, name="notifier", daemon=True)
        self._thread.start()

    def stop(self) -> None:
        self._stop.set()
        if self._thread is not None:
            self._thread.join(timeout=30)
        self._http.close()

    def _run(self) -> None:
        while not self._stop.is_set():
            try:
                self.round()
            except Exception:  # process boundary of the notifier thread
                log.exception("notifier round failed; retrying")
            self._stop.wait(0.5)

    def round(self) -> int:
        """Send every due notification once; returns how many were sent."""
        with transaction(self._sessions) as session:
            due = list(session.scalars(select(Notification).where(
                Notification.sent_at.is_(None), Notification.given_up.is_(False),
                Notification.next_attempt_at <= now()).order_by(Notification.id).limit(50)))
            work = [(n.id, n.channel, n.event, n.payload_json, n.delivery_id, n.team_id)
                    for n in due]
            teams = {t.id: (t.email, t.webhook_url, t.webhook_secret)
                     for t in session.scalars(select(Team).where(
                         Team.id.in_({w[5] for w in work})))}
        sent = 0
        for ident, channel, event, body, delivery_id, team_id in work:
            email, url, secret = teams.get(team_id, (None, None, None))
            error = None
            try:
                if channel == "mail":
                    if not email:
                        raise ValueError("the team has no e-mail address any more")
                    send_mail(self.settings, to=email, event=event, data=json.loads(body))
                else:
                    if not url:
                        raise ValueError("the team has no webhook URL any more")
                    key = self._sealer.open(secret) if secret else ""
                    headers = webhooks.sign(key, delivery_id=delivery_id, event=event,
                                            body=body.encode())
                    answer = outbound.post(self._http, url, content=body.encode(),
                                           headers=headers, allowed=self._allowed)
                    if answer.status_code >= 300:
                        raise ValueError(f"HTTP {answer.status_code} from {url}")
            except (OSError, ValueError, smtplib.SMTPException, httpx.HTTPError) as exc:
                error = f"{type(exc).__name__}: {exc}"
            self._record(ident, error)
            sent += error is None
        return sent

    def _record(self, ident: int, error: str | None) -> None:
        with transaction(self._sessions) as session:
            row = session.get(Notification, ident)
            assert row is not None
            row.attempts += 1
            if error is None:
                row.sent_at = now()
                log.info("%s %s for %s sent (attempt %d)", row.channel, row.event,
                         row.submission_id, row.attempts)
                return
            row.last_error = error
            if row.attempts >= self.settings.webhook_attempts:
                row.given_up = True
                log.warning("%s %s for %s given up after %d attempts: %s", row.channel,
                            row.event, row.submission_id, row.attempts, error)
            else:
                delay = self.settings.webhook_backoff_s * 2 ** (row.attempts - 1)
                row.next_attempt_at = utc(now()) + timedelta(seconds=delay)
                log.info("%s %s for %s failed (attempt %d, next in %.0f s): %s", row.channel,
                         row.event, row.submission_id, row.attempts, delay, error)


__all__ = [
    "MAIL_EVENTS",
    "NotificationPayload",
    "Notifier",
    "enqueue",
    "payload",
    "send_mail",
]
