"""Signed webhooks with retries against a real receiver on 127.0.0.1; replayed, altered and
stale deliveries are refused by the receiver's check."""

from __future__ import annotations

import json
import threading
import time
from collections.abc import Callable, Iterator
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from typing import Any

import pytest

from cluster.fake import FakePool
from service import webhooks
from tests.integration.service.harness import Served
from tests.unit.service.conftest import wait_for_status
from tests.unit.service.test_submissions import handle_of, setup_team

SECRET = "a-webhook-secret-of-the-team"


class Receiver:
    """Answers 500 to the first delivery (to force a retry), then checks each one."""

    def __init__(self) -> None:
        self.raw: list[tuple[dict[str, str], bytes]] = []
        self.accepted: list[dict[str, Any]] = []
        self.rejected: list[str] = []
        self.ids: set[str] = set()

    def seen(self, delivery: str) -> bool:
        if delivery in self.ids:
            return True
        self.ids.add(delivery)
        return False

    def handle(self, headers: dict[str, str], body: bytes) -> int:
        self.raw.append((headers, body))
        if len(self.raw) == 1:
            return 500
        try:
            webhooks.verify(SECRET, headers, body, seen=self.seen)
        except webhooks.WebhookRejected as exc:
            self.rejected.append(exc.reason)
            return 400
        self.accepted.append(json.loads(body))
        return 200


@pytest.fixture
def receiver() -> Iterator[tuple[Receiver, str]]:
    state = Receiver()

    class Handler(BaseHTTPRequestHandler):
        def do_POST(self) -> None:  # noqa: N802
            body = self.rfile.read(int(self.headers.get("Content-Length", "0")))
            code = state.handle(dict(self.headers.items()), body)
            self.send_response(code)
            self.send_header("Content-Length", "0")
            self.end_headers()

        def log_message(self, *args: Any) -> None:
            pass

    server = ThreadingHTTPServer(("127.0.0.1", 0), Handler)
    thread = threading.Thread(target=server.serve_forever, daemon=True)
    thread.start()
    yield state, f"http://127.0.0.1:{server.server_address[1]}/hook"
    server.shutdown()
    server.server_close()


def test_webhooks_are_signed_retried_and_not_replayable(
        start: Callable[..., Served], token: Callable[..., str], pool: FakePool,
        receiver: tuple[Receiver, str]) -> None:
    state, url = receiver
    served = start(webhook_allow="127.0.0.1/32")  # the receiver is on loopback
    tok = token("Alpha")
    with served.client(tok) as http:
        answer = http.patch("/v1/team", json={"webhook_url": url, "webhook_secret": SECRET})
        assert answer.status_code == 200 and answer.json()["webhook_secret_set"] is True
        assert SECRET not in answer.text
    with setup_team(served, tok, "Alpha") as http:
        sid = http.post("/v1/submissions", json={}).json()["id"]
        wait_for_status(http, sid, lambda b: b["state"] == "running")
        pool.finish(handle_of(served, sid), {"status": "success"})
        wait_for_status(http, sid, lambda b: b["state"] == "done")
    deadline = time.monotonic() + 15
    while len(state.accepted) < 2:
        assert time.monotonic() < deadline, (state.accepted, state.rejected)
        time.sleep(0.05)
    # the first delivery failed (HTTP 500) and was retried later, with the same delivery id
    assert sorted(a["event"] for a in state.accepted) == ["submission.finished",
                                                          "submission.started"]
    assert {a["submission"]["id"] for a in state.accepted} == {sid}
    first = state.raw[0][0]["X-HLVS-Delivery"]
    assert [h["X-HLVS-Delivery"] for h, _ in state.raw].count(first) == 2

    headers, body = state.raw[-1]
    with pytest.raises(webhooks.WebhookRejected) as replay:
        webhooks.verify(SECRET, headers, body, seen=state.seen)
    assert replay.value.reason == "replayed"
    with pytest.raises(webhooks.WebhookRejected) as altered:
        webhooks.verify(SECRET, headers, body.replace(b"success", b"failure") + b" ",
                        seen=lambda _d: False)
    assert altered.value.reason == "signature"
    stale = webhooks.sign(SECRET, delivery_id="d1", event="e", body=b"{}",
                          timestamp=int(time.time()) - 3600)
    with pytest.raises(webhooks.WebhookRejected) as old:
        webhooks.verify(SECRET, stale, b"{}", seen=lambda _d: False)
    assert old.value.reason == "stale"
    with pytest.raises(webhooks.WebhookRejected) as wrong_key:
        webhooks.verify("another-secret-entirely", headers, body, seen=lambda _d: False)
    assert wrong_key.value.reason == "signature"


def test_a_captured_delivery_does_not_verify_under_a_new_id_with_a_cut_body() -> None:
    """As found: the signature's input joined timestamp, id and body with '.', so moving the
    start of the body into the id kept the signature. The length-delimited signature (and the
    first form, accepted for the transition only where no field can hold a '.') refuse it."""
    body = b'{"event": "submission.finished", "score": {"red": 0, "blue": 3}}'
    headers = webhooks.sign(SECRET, delivery_id="9f" * 16, event="submission.finished",
                            body=body)
    assert webhooks.verify(SECRET, headers, body, seen=lambda _d: False) == "9f" * 16
    forged = {**headers, "X-HLVS-Delivery": "9f" * 16 + "." + body[:10].decode()}
    cut = body[11:]
    with pytest.raises(webhooks.WebhookRejected) as both:
        webhooks.verify(SECRET, forged, cut, seen=lambda _d: False)
    assert both.value.reason == "signature"
    legacy_only = {k: v for k, v in forged.items() if k != "X-HLVS-Signature-V2"}
    with pytest.raises(webhooks.WebhookRejected) as old:
        webhooks.verify(SECRET, legacy_only, cut, seen=lambda _d: False)
    assert old.value.reason == "signature"
    # the transition: a receiver still sent only the first form verifies a genuine delivery
    genuine = {k: v for k, v in headers.items() if k != "X-HLVS-Signature-V2"}
    assert webhooks.verify(SECRET, genuine, body, seen=lambda _d: False) == "9f" * 16
    with pytest.raises(webhooks.WebhookRejected) as ended:
        webhooks.verify(SECRET, genuine, body, seen=lambda _d: False, legacy=False)
    assert ended.value.reason == "missing"
