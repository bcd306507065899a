"""Fixtures shared by the integration tests."""

from __future__ import annotations

from collections.abc import Iterator

import docker
import docker.errors
import pytest


@pytest.fixture(scope="session")
def docker_client() -> Iterator[docker.DockerClient]:
    try:
        client = docker.from_env()
        client.ping()
    except docker.errors.DockerException as exc:
        pytest.skip(f"no Docker engine: {exc}")
    yield client
    client.close()
