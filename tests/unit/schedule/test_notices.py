"""The operator's notices (mail on a loopback SMTP server, signed webhooks on a loopback HTTP
server) and the scheduler's heartbeat in the state file, in the status and on the page."""

from __future__ import annotations

import json
import threading
from collections.abc import Iterator
from datetime import UTC, datetime, timedelta
from email import message_from_bytes
from email.message import Message
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from pathlib import Path
from typing import Any

import pytest

from contracts import webhooks
from hlvs.cli import main
from testkit.sftp import free_port
from tests.unit.schedule import fake_services
from tests.unit.schedule.test_schedule import COMPRESSED, FAKE, write_schedule
from tournament import Ledger, ScheduledMatchState, init_state
from tournament.notify import (
    NotifySettings,
    Outbox,
    Webhook,
    beat,
    scheduler_state,
    stopped,
)
from tournament.overview import tournament_overview

S = ScheduledMatchState
SECRET = "s3cret-of-the-league"


class Inbox:
    def __init__(self) -> None:
        self.messages: list[Message] = []

    async def handle_DATA(self, server: Any, session: Any, envelope: Any) -> str:  # noqa: N802
        self.messages.append(message_from_bytes(envelope.content))
        return "250 OK"


@pytest.fixture
def inbox() -> Iterator[tuple[Inbox, int]]:
    from aiosmtpd.controller import Controller

    handler = Inbox()
    port = free_port()
    controller = Controller(handler, hostname="127.0.0.1", port=port)
    controller.start()
    yield handler, port
    controller.stop()


@pytest.fixture
def receiver() -> Iterator[tuple[list[dict[str, Any]], str]]:
    """A webhook receiver that accepts only what :func:`contracts.webhooks.verify` accepts."""
    got: list[dict[str, Any]] = []
    seen: set[str] = set()

    def seen_before(delivery: str) -> bool:
        before = delivery in seen
        seen.add(delivery)
        return before

    class Handler(BaseHTTPRequestHandler):
        def do_POST(self) -> None:  # noqa: N802
            body = self.rfile.read(int(self.headers["Content-Length"]))
            try:
                webhooks.verify(SECRET, dict(self.headers), body, seen=seen_before)
            except webhooks.WebhookRejected:
                self.send_response(403)
                self.end_headers()
                return
            got.append({"event": self.headers["X-HLVS-Event"], **json.loads(body)})
            self.send_response(204)
            self.end_headers()

        def log_message(self, *args: Any) -> None:
            pass

    server = ThreadingHTTPServer(("127.0.0.1", 0), Handler)
    thread = threading.Thread(target=server.serve_forever, daemon=True)
    thread.start()
    yield got, f"http://127.0.0.1:{server.server_address[1]}/hook"
    server.shutdown()
    server.server_close()


@pytest.fixture
def fake() -> Iterator[None]:
    yield
    fake_services.DEAD_TEAMS.clear()
    fake_services.BROKEN.clear()


def test_failed_missed_and_logs_failed_are_mailed_and_posted_once(
    tmp_path: Path, inbox: tuple[Inbox, int], receiver: tuple[list[dict[str, Any]], str],
    fake: None,
) -> None:
    mails, port = inbox
    posted, url = receiver
    fake_services.BROKEN.add("m1")
    fake_services.DEAD_TEAMS.add("delta")
    path = write_schedule(
        tmp_path,
        COMPRESSED.replace("retry_s: 0.2", "retry_s: 0.2, delivery_attempts: 1")
        + "matches:\n  - {id: m1, red: alpha, blue: bravo, stream_start: '+3.5s',"
        " stream_length_s: 0.2}\n"
        "  - {id: m2, red: charlie, blue: delta, stream_start: '+3.9s', stream_length_s: 0.2}\n"
        "  - {id: m3, red: alpha, blue: delta, stream_start: '+0s', stream_length_s: 0.2}\n")
    (tmp_path / "secret").write_text(SECRET + "\n")
    state = tmp_path / "state.sqlite"
    assert main(["schedule", "run", str(path), "--state", str(state), "--exit-when-done",
                 "--services", FAKE, "--notify-mail", "ops@league.test", "--smtp",
                 f"127.0.0.1:{port}", "--notify-webhook", url, "--notify-webhook-secret-file",
                 str(tmp_path / "secret")]) == 0
    ledger = Ledger(state)
    assert [ledger.row(m).state for m in ("m1", "m2", "m3")] == [S.FAILED, S.LOGS_FAILED,
                                                                   S.MISSED]
    events = sorted((p["event"], p["match"]["id"]) for p in posted)
    assert events == [("match.failed", "m1"), ("match.logs_failed", "m2"),
                      ("match.missed", "m3")]
    assert all(p["tournament"] == "test cup" for p in posted)
    subjects = sorted(str(m["Subject"]) for m in mails.messages)
    assert subjects == ["[hlvs] test cup: match m1 FAILED",
                        "[hlvs] test cup: match m2: logs not delivered (LOGS_FAILED)",
                        "[hlvs] test cup: match m3 MISSED"]
    body = next(m for m in mails.messages if "m2" in str(m["Subject"])).get_payload()
    assert "delta failed" in str(body) and "hlvs logs deliver" in str(body)
    # a restart sends nothing again
    assert main(["schedule", "run", str(path), "--state", str(state), "--exit-when-done",
                 "--services", FAKE]) == 0
    assert len(posted) == 3 and len(mails.messages) == 3


def test_a_refused_webhook_is_retried_and_a_match_over_its_window_is_told(
    tmp_path: Path, receiver: tuple[list[dict[str, Any]], str],
) -> None:
    posted, url = receiver
    path = write_schedule(
        tmp_path, "matches:\n  - {id: m1, red: alpha, blue: bravo, stream_start: '+1h'}\n")
    state = tmp_path / "state.sqlite"
    init_state(path, state)
    ledger = Ledger(state)
    for to in (S.PULLING, S.PULLED, S.PLAYING):
        assert ledger.transition("m1", (S.PLANNED, S.PULLING, S.PULLED), to)
    outbox = Outbox(ledger, NotifySettings(webhooks=(Webhook(url=url, secret="wrong"),)))
    late = ledger.row("m1").stream_start + timedelta(seconds=5)
    assert outbox.scan(now=late - timedelta(seconds=10)) == 0  # still in its window
    assert outbox.scan(now=late) == 1 and outbox.scan(now=late) == 0
    assert outbox.send_due(now=late) == 0  # a wrong signature: refused (403), kept
    [notice] = outbox.notices()
    assert notice["attempts"] == 1 and "HTTP 403" in notice["last_error"]
    assert outbox.send_due(now=late) == 0  # not due again before its back-off
    fixed = Outbox(ledger, NotifySettings(webhooks=(Webhook(url=url, secret=SECRET),)))
    assert fixed.send_due(now=late + timedelta(seconds=31)) == 1
    assert [(p["event"], p["match"]["state"]) for p in posted] == [("match.over_window",
                                                                    "PLAYING")]


def test_a_dead_scheduler_is_said_in_the_status_and_the_page_and_notified(
    tmp_path: Path, capsys: pytest.CaptureFixture[str],
) -> None:
    path = write_schedule(
        tmp_path, "matches:\n  - {id: m1, red: alpha, blue: bravo, stream_start: '+1h'}\n")
    state = tmp_path / "state.sqlite"
    init_state(path, state)
    ledger = Ledger(state)
    now = datetime.now(UTC)
    beat(ledger, now=now - timedelta(seconds=10))
    assert scheduler_state(ledger).running
    assert main(["schedule", "status", "--state", str(state)]) == 0
    assert "not running" not in capsys.readouterr().out
    last = now - timedelta(minutes=5)
    beat(ledger, now=last)  # then killed (SIGKILL, a lost machine): no more heartbeats
    alive = scheduler_state(ledger)
    assert not alive.running and alive.waiting == 1
    since = last.isoformat(timespec="seconds")
    assert main(["schedule", "status", "--state", str(state)]) == 0
    out = capsys.readouterr().out
    assert out.splitlines()[0].startswith(f"scheduler not running since {since}")
    page = tournament_overview(ledger)
    assert page["scheduler"]["running"] is False
    assert page["warnings"][0].startswith(f"scheduler not running since {since}")
    sent: list[tuple[str, str]] = []
    outbox = Outbox(ledger, NotifySettings(mail_to=("ops@league.test",)))
    assert outbox.scan(scheduler=alive) == 1 and outbox.scan(scheduler=alive) == 0
    assert outbox.send_due(mailer=lambda s, to, event, data: sent.append((to, event))) == 1
    assert sent == [("ops@league.test", "scheduler.stopped")]
    stopped(ledger)  # a clean stop with every match final says so, and is not an alarm
    assert ledger.transition("m1", (S.PLANNED,), S.CANCELLED)
    alive = scheduler_state(ledger)
    assert not alive.running and alive.waiting == 0 and "every match is final" in alive.text
    assert tournament_overview(ledger)["warnings"] == []


def test_notification_options_are_checked(
    tmp_path: Path, capsys: pytest.CaptureFixture[str],
) -> None:
    path = write_schedule(
        tmp_path, "matches:\n  - {id: m1, red: alpha, blue: bravo, stream_start: '+1h'}\n")
    code = main(["schedule", "run", str(path), "--state", str(tmp_path / "s.sqlite"),
                 "--notify-webhook", "hooks.league.test/x", "--notify-mail", "ops"])
    err = capsys.readouterr().err
    assert code == 2
    assert "'hooks.league.test/x' is not a URL" in err
    assert "--notify-webhook-secret-file" in err and "'ops' is not a mail address" in err
