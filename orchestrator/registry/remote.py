"""A team's images as its registry sees them, before anything is pulled.

The one place that turns an image reference and a team's ``registry_auth`` into a
:class:`RegistryClient` (team login, password from the environment, or an Amazon ECR token) and
reads the image's manifest: its digest and its stored size. ``hlvs images pull``, a match's pull
step and the submission service's pre-flight check use it to refuse an image over the size limit,
or a team over its total, without pulling gigabytes first; ``hlvs registry enforce`` uses the
same client and the same size rule (shared layers counted once per team).
"""

from __future__ import annotations

import ipaddress
import os
from collections.abc import Mapping
from dataclasses import dataclass

from orchestrator.registry.auth import Credentials
from orchestrator.registry.client import Manifest, RegistryClient, union_bytes

DOCKER_HUB = "registry-1.docker.io"
INSECURE_ENV = "HLVS_INSECURE_REGISTRIES"  # comma-separated hosts spoken to over plain HTTP


def split_image(reference: str) -> tuple[str, str, str]:
    """(registry host, repository path in that registry, tag or digest) of
    ``[host/]repo[:tag]`` or ``[host/]repo@sha256:...``.

    A name without a host is on Docker Hub (``library/`` added for one-word names).
    """
    name, tag = reference, "latest"
    last = reference.rsplit("/", 1)[-1]
    if "@" in last:  # pinned by digest: the digest is the reference to read
        name, _, tag = reference.rpartition("@")
    elif ":" in last:
        name, _, tag = reference.rpartition(":")
    first, _, rest = name.partition("/")
    if rest and ("." in first or ":" in first or first == "localhost"):
        return first, rest, tag
    return DOCKER_HUB, name if "/" in name else f"library/{name}", tag


def registry_url(host: str, environ: Mapping[str, str] | None = None) -> str:
    """``http://`` for loopback hosts and hosts in ``$HLVS_INSECURE_REGISTRIES`` (as the Docker
    engine does for 127.0.0.0/8), ``https://`` otherwise."""
    environ = os.environ if environ is None else environ
    insecure = {h.strip() for h in environ.get(INSECURE_ENV, "").split(",") if h.strip()}
    name = host.rsplit(":", 1)[0].strip("[]") if host.count(":") <= 1 else host.strip("[]")
    loopback = name == "localhost"
    try:
        loopback = loopback or ipaddress.ip_address(name).is_loopback
    except ValueError:
        pass
    scheme = "http" if loopback or host in insecure else "https"
    return f"{scheme}://{host}"


@dataclass(frozen=True, slots=True, kw_only=True)
class RemoteImage:
    """One image reference as its registry stores it."""

    reference: str
    registry: str
    repository: str
    tag: str
    manifest: Manifest

    @property
    def digest(self) -> str:
        return self.manifest.digest

    @property
    def size_bytes(self) -> int:
        return self.manifest.size_bytes


def client_for(
    host: str, credentials: Credentials | None, *, environ: Mapping[str, str] | None = None
) -> RegistryClient:
    return RegistryClient(registry_url(host, environ), credentials=credentials)


def inspect_remote(
    reference: str, client: RegistryClient, *, platform: str = "linux/amd64"
) -> RemoteImage:
    """The manifest (digest, blobs, size) of ``reference`` for ``platform``; raises
    :class:`~orchestrator.registry.client.RegistryError`."""
    host, repository, tag = split_image(reference)
    manifest = client.image(repository, tag, platform=platform)
    return RemoteImage(
        reference=reference, registry=host, repository=repository, tag=tag, manifest=manifest
    )


def team_stored_bytes(images: list[RemoteImage]) -> int:
    """What a team's images occupy in registries: each layer once per registry."""
    return union_bytes(
        {f"{image.registry}/{digest}": size for digest, size in image.manifest.blobs.items()}
        for image in images
    )


__all__ = [
    "RemoteImage",
    "client_for",
    "inspect_remote",
    "registry_url",
    "split_image",
    "team_stored_bytes",
]
