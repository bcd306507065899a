"""The Docker adapter package: the only code that imports ``docker``.

``connect()`` gives a client or raises :class:`EngineUnavailable`; ``containers`` and ``networks``
hold the match's container and network calls, ``images`` the build, pull, push and inspect calls.
Everything the runner creates carries :data:`LABEL_PROJECT` plus the match id label, so cleanup
finds it after a crash.
"""

from __future__ import annotations

import os
from typing import TYPE_CHECKING

import docker
import docker.errors

from contracts import lazy_exports
from orchestrator.errors import EngineUnavailable

if TYPE_CHECKING:
    from orchestrator.engine.containers import DockerRuntime
    from orchestrator.engine.gpu import detect_nvidia

LABEL_PROJECT = "org.hlvs-runner"  # value: "1" on everything we create
LABEL_MATCH = "org.hlvs-runner.match"  # value: match id
LABEL_ROLE = "org.hlvs-runner.role"  # simulator | robot | network | helper
LABEL_TEAM = "org.hlvs-runner.team"  # red | blue
LABEL_ROBOT = "org.hlvs-runner.robot"  # player number
LABEL_SLURM_JOB = "org.hlvs-runner.slurm-job"  # the Slurm job a match runs in (its epilog)


def engine_endpoint() -> str:
    """Where the engine is: ``DOCKER_HOST``, or the local socket."""
    return os.environ.get("DOCKER_HOST") or "unix:///var/run/docker.sock"


def connect(*, timeout_s: float = 60.0) -> docker.DockerClient:
    """A client for the engine at ``DOCKER_HOST`` (or the local socket) that answered a ping."""
    endpoint = engine_endpoint()
    try:
        client = docker.DockerClient(base_url=endpoint, timeout=int(timeout_s))
        client.ping()
    except (docker.errors.DockerException, OSError) as exc:
        raise EngineUnavailable(endpoint=endpoint, reason=str(exc)) from exc
    return client


def engine_runtimes(client: docker.DockerClient) -> tuple[str, ...]:
    """The OCI runtimes the engine knows by name (``runc``, and those of its daemon.json)."""
    try:
        info = client.info()
    except (docker.errors.DockerException, OSError) as exc:
        raise EngineUnavailable(endpoint=engine_endpoint(), reason=str(exc)) from exc
    return tuple(sorted(info.get("Runtimes") or {}))


__all__ = [
    "DockerRuntime",
    "LABEL_MATCH",
    "LABEL_PROJECT",
    "LABEL_ROBOT",
    "LABEL_ROLE",
    "LABEL_SLURM_JOB",
    "LABEL_TEAM",
    "connect",
    "engine_endpoint",
    "engine_runtimes",
    "detect_nvidia",
]


if not TYPE_CHECKING:
    __getattr__, __dir__ = lazy_exports(__name__, {
        "orchestrator.engine.containers": ("DockerRuntime",),
        "orchestrator.engine.gpu": ("detect_nvidia",),
    })
