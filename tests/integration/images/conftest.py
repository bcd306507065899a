"""Fixtures for image tests: a Docker engine, a real registry (Debian's docker-registry) on a free
loopback port with htpasswd users (Basic auth) or with token auth and a token service on loopback,
a proxy that fails the first requests, and tiny images made with ``docker import``."""

from __future__ import annotations

import io
import os
import shutil
import subprocess
import tarfile
import threading
import time
import urllib.error
import urllib.request
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import docker
import docker.errors
import pytest

from testkit.sftp import free_port
from tests.conftest import TEST_LABEL
from tests.integration.images.token_issuer import ISSUER, SERVICE, TokenIssuer

REGISTRY_BINARY = "/usr/bin/docker-registry"
USERS = {
    "alpha": "alpha-secret", "beta": "beta-secret", "janitor": "janitor-secret",
    # What moto's Amazon ECR answers for a registry whose host starts with 127: the ECR test.
    "AWS": "127-auth-token",
}


@dataclass(frozen=True)
class Registry:
    host: str  # 127.0.0.1:PORT
    url: str  # http://127.0.0.1:PORT
    users: dict[str, str]
    config: Path
    auth: str = "basic"  # or "token"
    issuer: TokenIssuer | None = field(default=None, repr=False)


def _start_registry(
    root: Path, issuer: TokenIssuer | None = None
) -> tuple[subprocess.Popen[bytes], Registry]:
    if not os.path.exists(REGISTRY_BINARY) or shutil.which("htpasswd") is None:
        pytest.skip("docker-registry and htpasswd (apache2-utils) are needed")
    root.mkdir(parents=True, exist_ok=True)
    htpasswd = root / "htpasswd"
    lines = [
        subprocess.run(
            ["htpasswd", "-Bbn", user, password], check=True, capture_output=True, text=True
        ).stdout.strip()
        for user, password in USERS.items()
    ]
    htpasswd.write_text("\n".join(lines) + "\n")
    port = free_port()
    config = root / "config.yml"
    config.write_text(
        f"""version: 0.1
log:
  level: warn
storage:
  filesystem:
    rootdirectory: {root / "data"}
  delete:
    enabled: true
http:
  addr: 127.0.0.1:{port}
{_auth_section(htpasswd, issuer)}"""
    )
    log = (root / "registry.log").open("wb")
    process = subprocess.Popen([REGISTRY_BINARY, "serve", str(config)], stdout=log, stderr=log)
    url = f"http://127.0.0.1:{port}"
    deadline = time.monotonic() + 20
    while True:
        try:
            urllib.request.urlopen(url + "/v2/", timeout=2)
            break
        except urllib.error.HTTPError:
            break  # 401: up and asking for credentials
        except OSError:
            if process.poll() is not None or time.monotonic() > deadline:
                process.kill()
                pytest.fail(f"registry did not start; see {root / 'registry.log'}")
            time.sleep(0.1)
    return process, Registry(
        host=f"127.0.0.1:{port}", url=url, users=dict(USERS), config=config,
        auth="token" if issuer else "basic", issuer=issuer,
    )


def _auth_section(htpasswd: Path, issuer: TokenIssuer | None) -> str:
    if issuer is None:
        return f"""auth:
  htpasswd:
    realm: test-registry
    path: {htpasswd}
"""
    return f"""auth:
  token:
    realm: {issuer.realm}
    service: {SERVICE}
    issuer: {ISSUER}
    rootcertbundle: {issuer.cert_path}
"""


@pytest.fixture
def registry(tmp_path: Path, docker_client: docker.DockerClient) -> Iterator[Registry]:
    """A fresh registry per test, stopped and its pushed or pulled local images removed."""
    process, reg = _start_registry(tmp_path / "registry")
    try:
        yield reg
    finally:
        process.terminate()
        try:
            process.wait(timeout=10)
        except subprocess.TimeoutExpired:
            process.kill()
        _remove_images_of(docker_client, reg.host)


@pytest.fixture(params=["basic", "token"])
def any_registry(
    request: pytest.FixtureRequest, tmp_path: Path, docker_client: docker.DockerClient
) -> Iterator[Registry]:
    """A registry with Basic auth, then one with token auth (the same test runs on both)."""
    yield from _serve_registry(tmp_path, docker_client, token=request.param == "token")


@pytest.fixture
def token_registry(tmp_path: Path, docker_client: docker.DockerClient) -> Iterator[Registry]:
    """A registry with token auth; its token service runs on loopback in this process."""
    yield from _serve_registry(tmp_path, docker_client, token=True)


def _serve_registry(
    tmp_path: Path, docker_client: docker.DockerClient, *, token: bool
) -> Iterator[Registry]:
    issuer = TokenIssuer(folder=tmp_path / "issuer", users=dict(USERS)) if token else None
    server = issuer.start() if issuer else None
    process, reg = _start_registry(tmp_path / "registry", issuer)
    try:
        yield reg
    finally:
        process.terminate()
        try:
            process.wait(timeout=10)
        except subprocess.TimeoutExpired:
            process.kill()
        if server is not None:
            server.shutdown()
            server.server_close()
        _remove_images_of(docker_client, reg.host)


@dataclass
class FlakyProxy:
    """An HTTP proxy on loopback in front of a registry that makes the first ``failures`` pulls
    of the Docker engine fail: their manifest requests get 503 (a pull starts with the engine's
    ``GET /v2/``; clients whose User-Agent does not start with ``agent`` pass). Everything else
    passes through. ``seen`` records (method, path, status); ``pulls`` counts the engine's."""

    upstream: str  # 127.0.0.1:PORT
    failures: int = 2
    agent: str = "docker/"
    seen: list[tuple[str, str, int]] = field(default_factory=list)
    pulls: int = 0
    port: int = 0

    @property
    def host(self) -> str:
        return f"127.0.0.1:{self.port}"

    def start(self) -> Any:
        import http.client
        from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer

        proxy = self
        lock = threading.Lock()

        class Handler(BaseHTTPRequestHandler):
            protocol_version = "HTTP/1.1"

            def _forward(self) -> None:
                engine = self.headers.get("User-Agent", "").startswith(proxy.agent)
                with lock:
                    if engine and self.path == "/v2/":
                        proxy.pulls += 1
                    fail = engine and "/manifests/" in self.path and proxy.pulls <= proxy.failures
                if fail:
                    body = b'{"errors":[{"code":"UNAVAILABLE","message":"try again"}]}'
                    self.send_response(503)
                    self.send_header("Content-Type", "application/json")
                    self.send_header("Content-Length", str(len(body)))
                    self.end_headers()
                    if self.command != "HEAD":
                        self.wfile.write(body)
                    proxy.seen.append((self.command, self.path, 503))
                    return
                length = int(self.headers.get("Content-Length") or 0)
                data = self.rfile.read(length) if length else None
                upstream = http.client.HTTPConnection(proxy.upstream, timeout=60)
                upstream.putrequest(self.command, self.path, skip_host=True,
                                    skip_accept_encoding=True)
                upstream.putheader("Host", proxy.upstream)
                for name, value in self.headers.items():  # repeated headers (Accept) kept
                    if name.lower() not in ("host", "connection", "proxy-connection"):
                        upstream.putheader(name, value)
                upstream.endheaders(data)
                answer = upstream.getresponse()
                payload = answer.read()
                self.send_response(answer.status)
                for name, value in answer.getheaders():
                    if name.lower() in ("transfer-encoding", "connection"):
                        continue
                    if name.lower() == "content-length" and self.command != "HEAD":
                        continue
                    self.send_header(name, value)
                if self.command != "HEAD":
                    self.send_header("Content-Length", str(len(payload)))
                self.end_headers()
                if self.command != "HEAD":
                    self.wfile.write(payload)
                upstream.close()
                proxy.seen.append((self.command, self.path, answer.status))

            do_GET = do_HEAD = do_POST = do_PUT = do_PATCH = do_DELETE = _forward  # noqa: N815

            def log_message(self, format: str, *args: Any) -> None:
                pass

        server = ThreadingHTTPServer(("127.0.0.1", 0), Handler)
        self.port = server.server_address[1]
        threading.Thread(target=server.serve_forever, daemon=True).start()
        return server


@pytest.fixture
def flaky_proxy(registry: Registry) -> Iterator[FlakyProxy]:
    """A proxy in front of ``registry`` that fails the engine's first two manifest requests."""
    proxy = FlakyProxy(upstream=registry.host)
    server = proxy.start()
    try:
        yield proxy
    finally:
        server.shutdown()
        server.server_close()


def _remove_images_of(client: docker.DockerClient, host: str) -> None:
    # The raw listing: images.list() inspects each image and fails when another process removes
    # one meanwhile.
    for image in client.api.images():
        for tag in image.get("RepoTags") or ():
            if tag.startswith(host + "/"):
                try:
                    client.images.remove(tag, force=True)
                except docker.errors.APIError:
                    pass


MakeImage = Callable[[str, int], str]


@pytest.fixture
def make_image(docker_client: docker.DockerClient) -> Iterator[MakeImage]:
    """``make_image("repo:tag", payload_bytes)``: a tiny image with one file of random bytes."""
    made: list[str] = []

    def make(reference: str, payload_bytes: int) -> str:
        buffer = io.BytesIO()
        with tarfile.open(fileobj=buffer, mode="w") as tar:
            data = os.urandom(payload_bytes)
            info = tarfile.TarInfo("payload.bin")
            info.size = len(data)
            tar.addfile(info, io.BytesIO(data))
        repository, _, tag = reference.rpartition(":")
        docker_client.api.import_image_from_data(
            buffer.getvalue(),
            repository=repository,
            tag=tag,
            changes=[f'LABEL {TEST_LABEL}="1"'],
        )
        made.append(reference)
        return reference

    yield make
    for reference in made:
        try:
            docker_client.images.remove(reference, force=True)
        except docker.errors.APIError:
            pass


def push(client: docker.DockerClient, reference: str, user: str, password: str) -> str:
    """Push through the engine with a login; returns the manifest digest."""
    from orchestrator.engine.images import RegistryLogin
    from orchestrator.engine.images import push as engine_push

    repository, _, tag = reference.rpartition(":")
    login = RegistryLogin(username=user, password=password)
    return engine_push(client, repository, tag, auth=login)
