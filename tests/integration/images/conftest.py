"""Fixtures for image tests: a Docker engine, a real registry (Debian's docker-registry with
htpasswd users) on a free loopback port, and tiny images made with ``docker import``."""

from __future__ import annotations

import io
import os
import shutil
import subprocess
import tarfile
import time
import urllib.error
import urllib.request
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path

import docker
import docker.errors
import pytest

from orchestrator.delivery.local_sftp import free_port
from tests.conftest import TEST_LABEL

REGISTRY_BINARY = "/usr/bin/docker-registry"
USERS = {"alpha": "alpha-secret", "beta": "beta-secret", "janitor": "janitor-secret"}


@dataclass(frozen=True)
class Registry:
    host: str  # 127.0.0.1:PORT
    url: str  # http://127.0.0.1:PORT
    users: dict[str, str]
    config: Path


def _start_registry(root: Path) -> tuple[subprocess.Popen[bytes], Registry]:
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
auth:
  htpasswd:
    realm: test-registry
    path: {htpasswd}
"""
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
    return process, Registry(host=f"127.0.0.1:{port}", url=url, users=dict(USERS), config=config)


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
    from orchestrator.engine.images import RegistryAuth
    from orchestrator.engine.images import push as engine_push

    repository, _, tag = reference.rpartition(":")
    return engine_push(client, repository, tag, auth=RegistryAuth(username=user, password=password))
