"""What a hostile service can make `hlvs logs fetch` write, and what one team can learn of
another through the service: as the attack found them."""

from __future__ import annotations

import json
import os
import threading
from collections.abc import Callable
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from pathlib import Path
from typing import Any

import httpx
import pytest

from cluster.fake import FakePool
from contracts import files
from hlvs.cli import main
from tests.integration.service.harness import Served
from tests.unit.service.conftest import team_doc, wait_for_status
from tests.unit.service.test_submissions import handle_of, setup_team


class HostileService:
    """Answers a log listing with names that point outside the output folder."""

    def __init__(self, names: list[str]) -> None:
        listing = json.dumps({"team": names, "public": []}).encode()

        class Handler(BaseHTTPRequestHandler):
            def do_GET(self) -> None:  # noqa: N802
                body = listing if self.path.endswith("/logs") else b"owned\n"
                self.send_response(200)
                self.send_header("Content-Type", "application/json" if body is listing
                                 else "application/octet-stream")
                self.send_header("Content-Length", str(len(body)))
                self.end_headers()
                self.wfile.write(body)

            def log_message(self, *args: Any) -> None:
                pass

        self.server = ThreadingHTTPServer(("127.0.0.1", 0), Handler)
        self.url = f"http://127.0.0.1:{self.server.server_address[1]}"
        threading.Thread(target=self.server.serve_forever, daemon=True).start()

    def close(self) -> None:
        self.server.shutdown()
        self.server.server_close()


@pytest.fixture
def home(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    monkeypatch.setenv("HLVS_TOKEN", "hlvs_000000000000_" + "x" * 43)
    monkeypatch.chdir(tmp_path)
    return tmp_path


def test_logs_fetch_writes_only_under_out(home: Path, capsys: pytest.CaptureFixture[str]
                                          ) -> None:
    outside = home / "outside"
    outside.mkdir()
    out = home / "box" / "out"
    (out / "team").mkdir(parents=True)
    (out / "team" / "link").symlink_to(outside)  # a symlink already under --out
    escape = str(outside / "abs.txt")
    hostile = HostileService(["../../escaped.txt", escape, "a/../../up.txt", "link/through.txt",
                              "./dot.txt", "fine/ok.log"])
    try:
        code = main(["logs", "fetch", "--server", hostile.url, "sub_x", "--out", str(out)])
    finally:
        hostile.close()
    captured = capsys.readouterr()
    assert code == 2, captured
    report = json.loads(captured.out)
    assert report["files"] == ["team/fine/ok.log"]
    assert len(report["refused"]) == 5, report
    assert (out / "team" / "fine" / "ok.log").read_text() == "owned\n"
    written = {p.relative_to(home) for p in home.rglob("*") if p.is_file()}
    assert written == {Path("box/out/team/fine/ok.log")}, written
    assert list(outside.iterdir()) == []


HOST_KEY = "ssh-ed25519 AAAAC3NzaC1lZDI1NTE5AAAAILxD7/6Y8WqDP6ruY81+KhRD3hE1yx9rKAmI0vF5eFKN"


def _pair(start: Callable[..., Served], token: Callable[..., str]
          ) -> tuple[Served, dict[str, httpx.Client]]:
    served = start()
    secrets = {name: token(name, accepts_friendlies=True) for name in ("Alpha", "Beta")}
    clients = {}
    for name, secret in secrets.items():
        doc = team_doc(name, image=f"registry.{name.lower()}.example/{name.lower()}/robot")
        doc["players"]["1"]["dockerTag"] = "secret-tag"
        with served.client(secret) as http:
            assert http.put("/v1/team/files/team_config", json=doc).status_code == 201
        clients[name] = served.client(secret)
    return served, clients


def test_an_opponent_sees_neither_the_askers_log_target_nor_the_asker_its_images(
        start: Callable[..., Served], token: Callable[..., str], pool: FakePool) -> None:
    served, clients = _pair(start, token)
    alpha, beta = clients["Alpha"], clients["Beta"]
    target = {"type": "sftp", "credentials": {
        "hostname": "logs.alpha-private.example", "username": "alpha-user",
        "password": "pw-000000", "path": "/alpha/secret/folder",
        "host_key": HOST_KEY}}
    assert alpha.put("/v1/team/files/credentials", json=target).status_code == 201
    sid = alpha.post("/v1/submissions", json={"opponent": "Beta"}).json()["id"]
    wait_for_status(alpha, sid, lambda b: b["state"] == "running")
    handle = handle_of(served, sid)
    out = pool.results_dir(handle)
    pool.finish(handle, {"status": "success"})
    # the match's results name both sides' images, as a real match's do
    results = json.loads((out / files.RESULTS).read_text())
    results["robots"]["red-1"]["image"] = "registry.alpha.example/alpha/robot:secret-tag"
    results["robots"]["blue-1"]["image"] = "registry.beta.example/beta/robot:secret-tag"
    results["robots"]["blue-1"]["digest"] = "registry.beta.example/beta/robot@sha256:" + "b" * 64
    results["warnings"] = ["blue-1: registry.beta.example/beta/robot:secret-tag is large"]
    (out / files.RESULTS).write_text(json.dumps(results))
    wait_for_status(alpha, sid, lambda b: b["state"] == "done" and b["log_delivery"]
                    is not None)
    # Beta, the opponent, lists the friendly: not where Alpha's logs go
    seen_by_beta = beta.get("/v1/matches").text
    assert sid in seen_by_beta
    assert "alpha-private" not in seen_by_beta and "alpha-user" not in seen_by_beta
    assert "/alpha/secret/folder" not in seen_by_beta
    assert alpha.get("/v1/matches").json()[0]["log_delivery"] is not None  # its own: shown
    # Alpha, the asker, reads the results: its own image, not Beta's
    answer = alpha.get(f"/v1/submissions/{sid}/results")
    assert answer.status_code == 200
    shown = answer.json()
    assert shown["robots"]["red-1"]["image"].startswith("registry.alpha.example")
    assert "registry.beta.example" not in answer.text and "b" * 64 not in answer.text
    assert shown["robots"]["blue-1"]["exit_code"] == 0  # what is not private stays
    for http in clients.values():
        http.close()


def test_surrogates_in_secrets_are_refused_with_422(
        start: Callable[..., Served], token: Callable[..., str]) -> None:
    served = start()
    with served.client(token("Mallory")) as http:
        doc = team_doc("Mallory", image="registry.example.org/mallory/robot")
        doc["registry_auth"] = {"username": "m", "password": "pw\udc80"}
        body = json.dumps(doc).encode()  # ensure_ascii: "\udc80" as JSON escapes
        headers = {"Content-Type": "application/json"}
        answer = http.put("/v1/team/files/team_config", content=body, headers=headers)
        assert answer.status_code == 422, answer.text
        assert answer.json()["problems"][0]["pointer"] == "/registry_auth/password"
        s3 = {"type": "s3", "credentials": {"access_id": "AKIA", "access_secret": "s\ud800",
                                            "bucket": "b"}}
        answer = http.put("/v1/team/files/credentials", content=json.dumps(s3).encode(),
                          headers=headers)
        assert answer.status_code == 422, answer.text
        assert answer.json()["problems"][0]["pointer"] == "/credentials/access_secret"
        hook = http.patch("/v1/team", content=json.dumps(
            {"webhook_secret": "x" * 20 + "\udc80"}).encode(), headers=headers)
        assert hook.status_code == 422, hook.text


def test_a_log_name_that_is_not_utf8_is_listed_escaped_and_downloads(
        start: Callable[..., Served], token: Callable[..., str], pool: FakePool,
        tmp_path: Path) -> None:
    served = start()
    with setup_team(served, token("Alpha"), "Alpha") as http:
        sid = http.post("/v1/submissions", json={}).json()["id"]
        wait_for_status(http, sid, lambda b: b["state"] == "running")
        handle = handle_of(served, sid)
        pool.finish(handle, {"status": "success"})
        wait_for_status(http, sid, lambda b: b["state"] == "done")
        team = pool.results_dir(handle) / "teams" / "red" / "1"
        with open(os.path.join(os.fsencode(team), b"bad\xff\xfe.log"), "wb") as raw:
            raw.write(b"raw bytes name\n")
        (team / "passwd").symlink_to("/etc/passwd")  # a robot's link to a host file
        listing = http.get(f"/v1/submissions/{sid}/logs")
        assert listing.status_code == 200, listing.text
        names = listing.json()["team"]
        assert "1/bad\\xff\\xfe.log" in names, names
        assert "1/passwd" not in names
        got = http.get(f"/v1/submissions/{sid}/logs/team/1/bad\\xff\\xfe.log")
        assert got.status_code == 200 and got.text == "raw bytes name\n"


def test_deep_json_gets_422_with_a_pointer_on_every_route_with_a_body(
        start: Callable[..., Served], token: Callable[..., str]) -> None:
    """5,000 levels, as sent in the attack: every route that reads a body answers 422 with
    the pointer of the first value nested too deep (a typed route's parser gives up on it)."""
    served = start(max_upload_bytes=400_000)
    deep = b"[" * 5000 + b"]" * 5000
    headers = {"Content-Type": "application/json"}
    routes = [("PUT", "/v1/team/files/team_config"), ("POST", "/v1/team/files/credentials/check"),
              ("PATCH", "/v1/team"), ("POST", "/v1/submissions"), ("POST", "/v1/envs/"),
              ("POST", "/v1/envs/x/reset/"), ("POST", "/v1/envs/x/step/"),
              ("POST", "/v1/envs/x/monitor/start/")]
    schema = httpx.get(served.url + "/openapi.json").json()
    with_body = {(m.upper(), p) for p, ops in schema["paths"].items() for m, op in ops.items()
                 if "requestBody" in op}
    assert with_body <= {(m, p.replace("x", "{instance_id}")) if "envs/x" in p else (m, p)
                         for m, p in routes}, with_body
    with served.client(token("Mallory")) as http:
        for method, path in routes:
            answer = http.request(method, path, content=deep, headers=headers)
            assert answer.status_code == 422, (path, answer.status_code, answer.text[:200])
            pointer = answer.json()["problems"][0]["pointer"]
            assert pointer == "/0" * 65, (path, pointer[:80])
