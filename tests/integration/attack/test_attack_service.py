"""Attacks on the submission service by a hostile team, for real: the service on 127.0.0.1 over
HTTP, a real listener on 127.0.0.1 standing for the registry or webhook receiver the team
names, which records what would have been sent to it. The match pool and the image pre-flight
are the tests' fakes (no match is played), except where the real pre-flight is called."""

# ruff: noqa: F811  (the service tests' fixtures, imported below, are parameters here)
from __future__ import annotations

import json
import os
import socket
import stat
import threading
import time
import uuid
from collections.abc import Callable, Iterator
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from pathlib import Path
from typing import Any

import httpx
import pytest

from cluster.fake import FakePool
from service import Settings
from service.errors import InvalidInput
from tests.integration.service.harness import Served
from tests.unit.service.conftest import (  # noqa: F401  (fixtures)
    pool,
    settings,
    start,
    team_doc,
    token,
    wait_for_status,
)
from tests.unit.service.test_submissions import handle_of


class Listener:
    """A TCP listener on 127.0.0.1 that records every byte sent to it (and answers 200)."""

    def __init__(self) -> None:
        self.received: list[bytes] = []
        received = self.received

        class Handler(BaseHTTPRequestHandler):
            def _any(self) -> None:
                body = self.rfile.read(int(self.headers.get("Content-Length", "0") or 0))
                received.append(str(self.requestline).encode() + b"\n" +
                                bytes(self.headers) + body)
                self.send_response(200)
                self.send_header("Content-Length", "0")
                self.end_headers()

            do_GET = do_POST = do_PUT = do_HEAD = _any  # noqa: N815

            def log_message(self, *args: Any) -> None:
                pass

        self.server = ThreadingHTTPServer(("127.0.0.1", 0), Handler)
        self.port = int(self.server.server_address[1])
        threading.Thread(target=self.server.serve_forever, daemon=True).start()

    def close(self) -> None:
        self.server.shutdown()
        self.server.server_close()


@pytest.fixture
def listener() -> Iterator[Listener]:
    made = Listener()
    yield made
    made.close()


# --- class 1: the league's secrets -------------------------------------------------------------


def test_password_env_and_keyless_ecr_are_refused_without_telling_whether_a_variable_exists(
        start: Callable[..., Served], token: Callable[..., str], listener: Listener,
        monkeypatch: pytest.MonkeyPatch, settings: Settings) -> None:
    secret = "league-secret-" + uuid.uuid4().hex
    present, absent = "HLVS_TEST_PRESENT_" + uuid.uuid4().hex[:8], "HLVS_TEST_ABSENT_X"
    monkeypatch.setenv(present, secret)
    served = start()
    answers = {}
    with served.client(token("Mallory")) as http:
        for name in (present, absent):
            doc = team_doc("Mallory", image=f"127.0.0.1:{listener.port}/mallory/robot")
            doc["registry_auth"] = {"username": "mallory", "password_env": name}
            answer = http.put("/v1/team/files/team_config", json=doc)
            assert answer.status_code == 422, answer.text
            answers[name] = answer.text.replace(name, "NAME")
            pointers = [p["pointer"] for p in answer.json()["problems"]]
            assert "/registry_auth/password_env" in pointers
            assert secret not in answer.text
        assert answers[present] == answers[absent]  # nothing to probe
        ecr = team_doc("Mallory", image=f"127.0.0.1:{listener.port}/mallory/robot")
        ecr["registry_auth"] = {"ecr": {"region": "us-east-1"}}
        keyless = http.put("/v1/team/files/team_config", json=ecr)
        assert keyless.status_code == 422
        assert "/registry_auth/ecr" in [p["pointer"] for p in keyless.json()["problems"]]
        assert http.get("/v1/team/files/team_config").json() == []  # nothing stored
    # a file stored under older rules is refused too: a submission checks the stored file by
    # today's rules before its pre-flight, so no pull carries the variable's value anywhere
    from service.preflight import run
    from service.teamfiles import validated_team

    with pytest.raises(InvalidInput) as refused:
        stored = doc | {"registry_auth": {"username": "m", "password_env": present}}
        run(validated_team(stored), settings=settings.with_(preflight="images"))
    assert "/registry_auth/password_env" in str(refused.value.problems)
    assert listener.received == []


def test_credentials_never_read_host_files_for_a_team(
        start: Callable[..., Served], token: Callable[..., str], tmp_path: Path) -> None:
    host_key = tmp_path / "host_secret_key"
    host_key.write_text("-----BEGIN OPENSSH PRIVATE KEY-----\nhost\n"
                        "-----END OPENSSH PRIVATE KEY-----\n")
    served = start()
    body = {"hostname": "203.0.113.9", "username": "team", "path": "logs"}
    answers = []
    with served.client(token("Mallory")) as http:
        for path in (str(host_key), str(tmp_path / "no_such_file")):
            document = {"type": "sftp", "credentials": {**body, "private_key": path,
                                                        "known_hosts": path}}
            answer = http.put("/v1/team/files/credentials", json=document)
            assert answer.status_code == 422, answer.text
            pointers = {p["pointer"] for p in answer.json()["problems"]}
            assert {"/credentials/private_key", "/credentials/known_hosts"} <= pointers
            assert "host" + "\n" not in answer.text
            answers.append(answer.text.replace(path, "PATH"))
    assert answers[0] == answers[1]  # an existing host file and a missing one answer alike


def _modes(root: Path) -> dict[str, int]:
    found = {".": stat.S_IMODE(root.stat().st_mode)}
    for folder, dirs, names in os.walk(root):
        for name in dirs + names:
            path = Path(folder) / name
            found[str(path.relative_to(root))] = stat.S_IMODE(path.lstat().st_mode)
    return found


def test_secrets_are_sealed_at_rest_never_shown_back_and_files_are_private(
        start: Callable[..., Served], token: Callable[..., str], pool: FakePool) -> None:
    registry_password = "registry-pw-" + uuid.uuid4().hex
    s3_secret = "s3-secret-" + uuid.uuid4().hex
    hook_secret = "hook-secret-" + uuid.uuid4().hex
    served = start()
    with served.client(token("Alpha")) as http:
        doc = team_doc("Alpha")
        doc["registry_auth"] = {"username": "alpha", "password": registry_password}
        assert http.put("/v1/team/files/team_config", json=doc).status_code == 201
        credentials = {"type": "s3", "credentials": {
            "access_id": "AKIAALPHA", "access_secret": s3_secret, "bucket": "alpha-logs"}}
        assert http.put("/v1/team/files/credentials", json=credentials).status_code == 201
        assert http.patch("/v1/team", json={"webhook_secret": hook_secret}).status_code == 200
        shown = http.get("/v1/team/files/team_config/1").text + \
            http.get("/v1/team/files/credentials/1").text + http.get("/v1/team").text
        for secret in (registry_password, s3_secret, hook_secret):
            assert secret not in shown
        assert json.loads(http.get("/v1/team/files/team_config/1").text)[
            "content"]["registry_auth"]["password"] == "***"
        sid = http.post("/v1/submissions", json={}).json()["id"]
        wait_for_status(http, sid, lambda b: b["state"] == "running")
    data = served.settings.data_dir
    stored = b"".join(p.read_bytes() for p in data.rglob("service.sqlite*"))
    for secret in (registry_password, s3_secret, hook_secret):
        assert secret.encode() not in stored
    key = data.parent / "data.key"
    assert stat.S_IMODE(key.stat().st_mode) == 0o600
    # the match gets the password it needs to pull, in a file only the service can read
    team_red = Path(handle_of(served, sid)) / "config" / "team_red.json"
    assert json.loads(team_red.read_text())["registry_auth"]["password"] == registry_password
    modes = _modes(data)
    wrong = {name: oct(mode) for name, mode in modes.items()
             if mode not in (0o700 if (data / name).is_dir() else 0o600,)
             and not name.startswith("matches/" + Path(handle_of(served, sid)).name + "/out")}
    assert wrong == {}
    assert modes["service.sqlite"] == 0o600 and modes["."] == 0o700


# --- class 3: requests the team points the service at -------------------------------------------


def test_webhooks_never_reach_the_leagues_own_addresses(
        start: Callable[..., Served], token: Callable[..., str], pool: FakePool,
        listener: Listener, settings: Settings) -> None:
    served = start()
    local_url = f"http://127.0.0.1:{listener.port}/hook"
    with served.client(token("Mallory")) as http:
        for url in (local_url, "http://169.254.169.254/latest/meta-data/",
                    "http://10.0.0.1/", "http://[::1]:80/", f"http://localhost:{listener.port}/"):
            answer = http.patch("/v1/team", json={"webhook_url": url})
            assert answer.status_code == 422, (url, answer.text)
            assert answer.json()["problems"][0]["pointer"] == "/webhook_url"
    # a URL that passed when it was written but resolves to the league's own address when
    # sent (DNS rebinding; here the stored row names it outright): checked again, not sent
    from sqlalchemy import update

    from service.db import Team, make_engine, session_factory, transaction

    engine = make_engine(settings.db_url)
    with transaction(session_factory(engine)) as session:
        session.execute(update(Team).where(Team.name == "Mallory").values(webhook_url=local_url))
    engine.dispose()
    with served.client(token("Mallory")) as http:
        assert http.put("/v1/team/files/team_config",
                        json=team_doc("Mallory")).status_code == 201
        sid = http.post("/v1/submissions", json={}).json()["id"]
        wait_for_status(http, sid, lambda b: b["state"] == "running")
        pool.finish(handle_of(served, sid), {"status": "success"})
        wait_for_status(http, sid, lambda b: b["state"] == "done")
    from sqlalchemy import select

    from service.db import Notification

    engine = make_engine(settings.db_url)
    deadline = time.monotonic() + 10
    while True:
        with transaction(session_factory(engine)) as session:
            errors = [n.last_error for n in session.scalars(select(Notification))]
        if errors and all(errors):
            break
        assert time.monotonic() < deadline, errors
        time.sleep(0.1)
    engine.dispose()
    assert all("not a public address" in e for e in errors if e), errors
    assert listener.received == []
    served.stop()
    # the operator may allow a network: then the same listener is reached (what it would see)
    allowed = start(webhook_allow="127.0.0.0/8")
    with allowed.client(token("Mallory")) as http:
        assert http.patch("/v1/team", json={"webhook_url": local_url}).status_code == 200
        sid = http.post("/v1/submissions", json={}).json()["id"]
        wait_for_status(http, sid, lambda b: b["state"] == "running")
    deadline = time.monotonic() + 10
    while not listener.received:
        assert time.monotonic() < deadline
        time.sleep(0.05)
    assert b"submission.started" in listener.received[0]


# --- class 4: memory before authentication ------------------------------------------------------


def _stream_chunked(url: str, request_line: bytes, limit: int = 200_000_000
                    ) -> tuple[bytes, int]:
    """Send a chunked body (no Content-Length) until the service answers; (answer, bytes
    sent by then)."""
    host, port = url.removeprefix("http://").split(":")
    chunk = b"x" * 65536
    sent = 0
    answer = b""
    forged = "hlvs_" + "a" * 12 + "_" + "b" * 43  # well formed, unknown: a database look-up
    with socket.create_connection((host, int(port)), timeout=10) as sock:
        sock.sendall(request_line + b"\r\nHost: x\r\nAuthorization: Bearer " +
                     forged.encode() + b"\r\nContent-Type: application/json\r\n"
                     b"Transfer-Encoding: chunked\r\n\r\n")
        sock.setblocking(False)
        while sent < limit and b"\r\n\r\n" not in answer:
            try:
                answer += sock.recv(65536)
                continue
            except BlockingIOError:
                pass
            try:
                sock.sendall(b"%x\r\n" % len(chunk) + chunk + b"\r\n")
                sent += len(chunk)
            except BlockingIOError:
                time.sleep(0.001)
    return answer, sent


def test_a_chunked_body_is_cut_at_the_limit_before_the_token_is_looked_at(
        start: Callable[..., Served]) -> None:
    served = start()
    for request_line in (b"POST /v1/submissions HTTP/1.1", b"PATCH /v1/team HTTP/1.1",
                         b"PUT /v1/team/files/team_config HTTP/1.1"):
        answer, sent = _stream_chunked(served.url, request_line)
        # answered while the body was still coming, long before its 200 MB: 413 where the
        # body is read before the token, 401 where the token is checked first
        assert answer.startswith((b"HTTP/1.1 413", b"HTTP/1.1 401")), answer[:200]
        assert sent < 20_000_000, (request_line, sent)
        if b"submissions" in request_line:
            assert answer.startswith(b"HTTP/1.1 413"), answer[:200]
    # and a declared Content-Length over the limit is refused without reading
    too_big = httpx.put(served.url + "/v1/team/files/team_config", content=b"{" * 30_000,
                        headers={"Content-Type": "application/json"})
    assert too_big.status_code == 413


# --- class 9: bad input gets 4xx with the field, never 500 --------------------------------------


def test_hostile_json_gets_a_4xx_naming_the_field(
        start: Callable[..., Served], token: Callable[..., str]) -> None:
    served = start(max_upload_bytes=400_000)
    with served.client(token("Mallory")) as http:
        headers = {"Content-Type": "application/json"}
        deep = b"[" * 100_000 + b"]" * 100_000
        digits = b'{"name": ' + b"9" * 5000 + b"}"
        for path in ("/v1/team/files/team_config", "/v1/team/files/team_config/check",
                     "/v1/submissions"):
            for body in (deep, digits, b'{"name": 1e999}', b'{"name": NaN}'):
                answer = http.request("POST" if "check" in path or "sub" in path else "PUT",
                                      path, content=body, headers=headers)
                assert 400 <= answer.status_code < 500, (path, body[:20], answer.text[:300])
                assert "Traceback" not in answer.text
        huge = http.get("/v1/team/files/team_config/" + "9" * 30)
        assert huge.status_code == 422 and huge.json()["problems"][0]["pointer"] == "/version"
        version = http.post("/v1/submissions", json={"team_config_version": 1e30})
        assert version.status_code == 422
        assert version.json()["problems"][0]["pointer"] == "/team_config_version"
        env = http.post("/v1/envs/", json={"env_id": "hlvs/Kick-v0",
                                           "kwargs": {"max_episode_s": 1e308}})
        assert env.status_code == 422, env.text
        assert env.json()["problems"][0]["pointer"] == "/kwargs/max_episode_s"
        cmd = team_doc("Mallory")
        cmd["players"]["1"]["dockerCmd"] = "python3 -c 'unclosed"
        unclosed = http.put("/v1/team/files/team_config", json=cmd)
        assert unclosed.status_code == 422
        assert "/players/1/dockerCmd" in [p["pointer"] for p in unclosed.json()["problems"]]
