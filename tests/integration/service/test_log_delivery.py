"""A team's logs delivered after its test match to the target of the credentials it uploaded:
real SFTP (asyncssh) and S3 (moto) servers on 127.0.0.1, the served service; the match output
comes from the fake pool (real matches deliver in test_real_matches.py)."""

from __future__ import annotations

import socket
import threading
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from pathlib import Path
from typing import Any

import httpx
import pytest

from cluster.fake import FakePool
from service import Settings
from testkit.s3 import MotoServer
from testkit.sftp import AsyncsshServer
from tests.integration.delivery.conftest import (  # noqa: F401 (fixtures)
    asyncssh_server,
    check_manifest,
    moto,
    read_tree,
)
from tests.integration.delivery.test_delivery_s3 import ensure_bucket, read_bucket, s3_body
from tests.integration.delivery.test_delivery_sftp import OTHER_KEY, sftp_body
from tests.integration.service.conftest import TokenMaker
from tests.integration.service.harness import Served, serve
from tests.unit.service.conftest import team_doc, wait_for_status


def play(served: Served, pool: FakePool, http: httpx.Client) -> dict[str, Any]:
    """Submit, let the fake pool finish the match, wait until the delivery has ended."""
    sid = http.post("/v1/submissions", json={}).json()["id"]
    wait_for_status(http, sid, lambda b: b["state"] == "running", 30)
    [handle] = [h for h, m in pool.handles.items() if m.startswith(sid)]
    pool.finish(handle, {"status": "success"})
    return wait_for_status(http, sid, lambda b: b["state"] == "done"
                           and b["log_delivery"] is not None
                           and b["log_delivery"]["state"] != "pending", 30)


@pytest.mark.parametrize("db_url", ["sqlite"], indirect=True)
def test_logs_go_to_the_uploaded_sftp_or_s3_target_and_failures_say_why(
        settings: Settings, make_token: TokenMaker, asyncssh_server: AsyncsshServer,  # noqa: F811
        moto: MotoServer, tmp_path: Path) -> None:  # noqa: F811
    pool = FakePool(slots=3)
    # the test servers are on loopback: the operator allows it (public addresses only else)
    served = serve(settings.with_(worker_poll_s=0.1, match_slots=3, video=False,
                                  log_target_allow="127.0.0.0/8"),
                   start_worker=True, pool_factory=lambda _s: pool,
                   preflight=lambda _doc, _s: 0.01)
    ensure_bucket(moto.endpoint_url, moto.admin, "team-logs")
    targets = {
        "Alpha": {"type": "sftp", "credentials": sftp_body(asyncssh_server)},
        "Beta": {"type": "s3", "credentials": s3_body(moto.endpoint_url, moto.admin,
                                                       "team-logs")},
        "Gamma": {"type": "sftp", "credentials": sftp_body(asyncssh_server,
                                                            password="not-the-password")},
    }
    clients = {}
    try:
        for name, credentials in targets.items():
            http = clients[name] = served.client(make_token(team=name))
            assert http.put("/v1/team/files/team_config", json=team_doc(name)).status_code == 201
            stored = http.put("/v1/team/files/credentials", json=credentials)
            assert stored.status_code == 201, stored.text
        ended = {name: play(served, pool, http) for name, http in clients.items()}

        alpha = ended["Alpha"]
        assert alpha["log_delivery"]["state"] == "delivered", alpha
        assert "sftp://hlvs@127.0.0.1" in alpha["log_delivery"]["detail"]
        remote = read_tree(asyncssh_server.root / "upload" / "hlvs")
        manifest = check_manifest(remote, f"{alpha['match_id']}/Alpha")
        assert [f["path"] for f in manifest["files"]] == ["1/stdout.log"]
        assert remote[f"{alpha['match_id']}/Alpha/1/stdout.log"] == b"red robot log\n"
        assert not any("blue" in key for key in remote)  # never the other team's logs

        beta = ended["Beta"]
        assert beta["log_delivery"]["state"] == "delivered", beta
        bucket = read_bucket(moto.endpoint_url, moto.admin, "team-logs", "hlvs/2026")
        check_manifest(bucket, f"{beta['match_id']}/Beta")
        assert bucket[f"{beta['match_id']}/Beta/1/stdout.log"] == b"red robot log\n"

        gamma = ended["Gamma"]
        assert gamma["state"] == "done", gamma  # a failed delivery does not fail the match
        assert gamma["log_delivery"]["state"] == "failed"
        assert "(auth:" in gamma["log_delivery"]["detail"], gamma["log_delivery"]
        assert "not-the-password" not in str(gamma)
        assert not any(key.startswith(f"{gamma['match_id']}/")
                       for key in read_tree(asyncssh_server.root / "upload" / "hlvs"))
        # the logs stay downloadable from the service, delivered or not
        for name, body in ended.items():
            own = clients[name].get(f"/v1/submissions/{body['id']}/logs/team/1/stdout.log")
            assert own.status_code == 200 and own.text == "red robot log\n"

        # no credentials uploaded: nothing to deliver
        delta = served.client(make_token(team="Delta"))
        clients["Delta"] = delta
        assert delta.put("/v1/team/files/team_config", json=team_doc("Delta")).status_code == 201
        sid = delta.post("/v1/submissions", json={}).json()["id"]
        wait_for_status(delta, sid, lambda b: b["state"] == "running", 30)
        [handle] = [h for h, m in pool.handles.items() if m.startswith(sid)]
        pool.finish(handle, {"status": "success"})
        done = wait_for_status(delta, sid, lambda b: b["state"] == "done", 30)
        assert done["log_delivery"] is None
    finally:
        for http in clients.values():
            http.close()
        served.stop()


@pytest.mark.parametrize("db_url", ["sqlite"], indirect=True)
def test_a_log_target_on_the_leagues_own_network_is_refused_at_upload_and_at_delivery(
        settings: Settings, make_token: TokenMaker, asyncssh_server: AsyncsshServer,  # noqa: F811
        moto: MotoServer, monkeypatch: pytest.MonkeyPatch) -> None:  # noqa: F811
    """As the attack found it: credentials naming the league's loopback SFTP and S3 servers.
    Refused when uploaded; a target stored while the operator allowed loopback, and a name
    that resolves to loopback (rebinding), are refused again when the logs are delivered, and
    the servers receive nothing."""
    pool = FakePool(slots=2)
    ensure_bucket(moto.endpoint_url, moto.admin, "league-logs")
    sftp = {"type": "sftp", "credentials": sftp_body(asyncssh_server)}
    s3 = {"type": "s3", "credentials": s3_body(moto.endpoint_url, moto.admin, "league-logs")}
    strict = settings.with_(worker_poll_s=0.1, match_slots=2, video=False)
    served = serve(strict, start_worker=True, pool_factory=lambda _s: pool,
                   preflight=lambda _doc, _s: 0.01)
    http = served.client(make_token(team="Mallory"))
    try:
        for hostname in ("127.0.0.1", "169.254.169.254", "10.1.2.3", "::1", "localhost"):
            body = {"type": "sftp", "credentials": {**sftp["credentials"], "hostname": hostname}}
            for path in ("/v1/team/files/credentials", "/v1/team/files/credentials/check"):
                answer = (http.put if path.endswith("credentials") else http.post)(path, json=body)
                problems = answer.json()["problems"]
                assert answer.status_code in (200, 422), answer.text
                assert any(p["pointer"] == "/credentials/hostname" and "public address" in
                           p["message"] and p["severity"] == "error" for p in problems), problems
        for url in (moto.endpoint_url, "http://169.254.169.254/", "http://[fd00::1]:9000"):
            body = {"type": "s3", "credentials": {**s3["credentials"], "endpoint_url": url}}
            answer = http.put("/v1/team/files/credentials", json=body)
            assert answer.status_code == 422, answer.text
            assert answer.json()["problems"][0]["pointer"] == "/credentials/endpoint_url"
        assert http.get("/v1/team/files/credentials").json() == []
    finally:
        http.close()
        served.stop()

    # stored while the operator allowed loopback, delivered after it no longer does
    allowing = serve(strict.with_(log_target_allow="127.0.0.0/8"), pool_factory=lambda _s: pool,
                     preflight=lambda _doc, _s: 0.01)
    clients = {name: allowing.client(make_token(team=name)) for name in ("Sftp", "S3", "Named")}
    named = {"type": "s3", "credentials": s3_body(
        moto.endpoint_url.replace("127.0.0.1", "logs.example.org"), moto.admin, "league-logs")}
    for name, document in (("Sftp", sftp), ("S3", s3), ("Named", named)):
        assert clients[name].put("/v1/team/files/team_config",
                                 json=team_doc(name)).status_code == 201
        stored = clients[name].put("/v1/team/files/credentials", json=document)
        assert stored.status_code == 201, stored.text
    for http in clients.values():
        http.close()
    allowing.stop()

    real = socket.getaddrinfo

    def getaddrinfo(host: Any, *args: Any, **kwargs: Any) -> Any:
        # the name passed its check when written; it points home now (DNS rebinding)
        return real("127.0.0.1" if host == "logs.example.org" else host, *args, **kwargs)

    monkeypatch.setattr(socket, "getaddrinfo", getaddrinfo)
    before_sftp = read_tree(asyncssh_server.root / "upload" / "hlvs")
    served = serve(strict, start_worker=True, pool_factory=lambda _s: pool,
                   preflight=lambda _doc, _s: 0.01)
    try:
        for name in ("Sftp", "S3", "Named"):
            with served.client(make_token(team=name)) as http:
                ended = play(served, pool, http)
            delivery = ended["log_delivery"]
            assert delivery["state"] == "failed", (name, delivery)
            assert "not a public address" in delivery["detail"], (name, delivery)
            assert "HLVS_SERVICE_LOG_TARGET_ALLOW" in delivery["detail"]
        assert read_tree(asyncssh_server.root / "upload" / "hlvs") == before_sftp
        assert read_bucket(moto.endpoint_url, moto.admin, "league-logs", "") == {}
    finally:
        served.stop()


class InternalS3:
    """An internal HTTP server standing in for S3: HEAD answers 200, every write 400 with an
    error body that only the league's network should see."""

    BODY = (b"<Error><Code>InvalidArgument</Code><Message>internal-answer: db.league.lan "
            b"password hunter2</Message></Error>")

    def __init__(self) -> None:
        body = self.BODY

        class Handler(BaseHTTPRequestHandler):
            def do_HEAD(self) -> None:  # noqa: N802
                self.send_response(200)
                self.send_header("Content-Length", "0")
                self.end_headers()

            def do_PUT(self) -> None:  # noqa: N802
                self.rfile.read(int(self.headers.get("Content-Length", "0") or 0))
                self.send_response(400)
                self.send_header("Content-Type", "application/xml")
                self.send_header("Content-Length", str(len(body)))
                self.end_headers()
                self.wfile.write(body)

            do_POST = do_PUT  # noqa: N815

            def log_message(self, *args: Any) -> None:
                pass

        self.server = ThreadingHTTPServer(("127.0.0.1", 0), Handler)
        self.url = f"http://127.0.0.1:{self.server.server_address[1]}"
        threading.Thread(target=self.server.serve_forever, daemon=True).start()

    def close(self) -> None:
        self.server.shutdown()
        self.server.server_close()


@pytest.mark.parametrize("db_url", ["sqlite"], indirect=True)
def test_a_failed_delivery_shows_the_team_nothing_the_server_answered(
        settings: Settings, make_token: TokenMaker, asyncssh_server: AsyncsshServer,  # noqa: F811
        moto: MotoServer) -> None:  # noqa: F811
    """An SFTP server with another host key than the pinned one, an S3 server answering an
    error body: the status names the kind of failure, never the server's host key or answer
    (the operator allows loopback, as for a league-internal server)."""
    pool = FakePool(slots=2)
    served = serve(settings.with_(worker_poll_s=0.1, match_slots=2, video=False,
                                  log_target_allow="127.0.0.0/8"),
                   start_worker=True, pool_factory=lambda _s: pool,
                   preflight=lambda _doc, _s: 0.01)
    internal = InternalS3()
    targets = {
        "Keyed": {"type": "sftp", "credentials": sftp_body(asyncssh_server, host_key=OTHER_KEY)},
        "Answer": {"type": "s3", "credentials": s3_body(internal.url, moto.admin, "team-logs")},
    }
    try:
        for name, document in targets.items():
            with served.client(make_token(team=name)) as http:
                assert http.put("/v1/team/files/team_config",
                                json=team_doc(name)).status_code == 201
                assert http.put("/v1/team/files/credentials", json=document).status_code == 201
                delivery = play(served, pool, http)["log_delivery"]
                assert delivery["state"] == "failed", delivery
                detail = delivery["detail"]
                if name == "Keyed":
                    assert "(host_key:" in detail, detail
                    served_key = asyncssh_server.host_key.split()[1]
                    assert served_key not in detail and "AAAA" not in detail, detail
                else:
                    assert "(path:" in detail, detail
                    assert "internal-answer" not in detail and "hunter2" not in detail, detail
                    assert "InvalidArgument" not in detail, detail
    finally:
        internal.close()
        served.stop()
