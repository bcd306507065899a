"""Image calls on the Docker engine: build, import, inspect, tag, push, pull, remove.

The only module that talks to the engine about images. Engine errors are translated here, once:
a failed pull becomes :class:`ImagePullError` whose ``reason`` says what went wrong in the
words an operator can act on (authentication, unknown tag, unreachable registry).
"""

from __future__ import annotations

import logging
import re
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import docker
import docker.errors
import requests.exceptions

from orchestrator.errors import ImageError, ImagePullError, InfrastructureError
from orchestrator.image_origin import registry_of

log = logging.getLogger(__name__)

LineSink = Callable[[str], None]


@dataclass(frozen=True, slots=True, kw_only=True)
class ImageInfo:
    """What the engine knows about one local image."""

    id: str  # sha256:...
    tags: tuple[str, ...]
    repo_digests: tuple[str, ...]  # repo@sha256:... (present once pushed or pulled)
    size_bytes: int
    labels: Mapping[str, str]
    created_unix: int = 0  # filled by list_labelled
    volumes: tuple[str, ...] = ()  # the image's VOLUME paths


@dataclass(frozen=True, slots=True, kw_only=True)
class RegistryLogin:
    """Credentials for one registry, as the engine's ``auth_config`` wants them."""

    username: str
    password: str

    def as_auth_config(self) -> dict[str, str]:
        return {"username": self.username, "password": self.password}


class BuildFailed(ImageError):
    """``docker build`` stopped with an error; ``log_path`` holds the whole build output."""

    def __init__(self, *, image: str, reason: str, log_path: Path) -> None:
        self.log_path = log_path
        super().__init__(image=image, reason=f"build failed: {reason} (build log: {log_path})")


def inspect(client: docker.DockerClient, reference: str) -> ImageInfo | None:
    """The local image ``reference`` (name:tag, id or repo@digest), or None when absent."""
    try:
        attrs = client.api.inspect_image(reference)
    except docker.errors.ImageNotFound:
        return None
    except docker.errors.APIError as exc:
        if exc.status_code == 404:
            return None
        raise InfrastructureError(f"cannot inspect image {reference}: {exc.explanation}") from exc
    config = attrs.get("Config") or {}
    return ImageInfo(
        id=str(attrs["Id"]),
        tags=tuple(attrs.get("RepoTags") or ()),
        repo_digests=tuple(attrs.get("RepoDigests") or ()),
        size_bytes=int(attrs.get("Size") or 0),
        labels=dict(config.get("Labels") or {}),
        volumes=tuple(sorted(config.get("Volumes") or {})),
    )


def build(
    client: docker.DockerClient,
    *,
    context_dir: Path,
    tag: str,
    build_args: Mapping[str, str],
    labels: Mapping[str, str],
    log_path: Path,
    network_mode: str | None,
    on_step: LineSink,
) -> ImageInfo:
    """Build ``context_dir/Dockerfile`` as ``tag`` with the classic builder.

    Every output line goes to ``log_path``; each ``Step n/m`` line also to ``on_step``.
    """
    log_path.parent.mkdir(parents=True, exist_ok=True)
    with log_path.open("w", encoding="utf-8") as out:
        try:
            stream = client.api.build(
                path=str(context_dir),
                tag=tag,
                buildargs=dict(build_args),
                labels=dict(labels),
                network_mode=network_mode,
                rm=True,
                forcerm=True,
                pull=False,
                decode=True,
            )
            error = _follow_build(stream, out, on_step)
        except docker.errors.APIError as exc:
            error = str(exc.explanation or exc)
        if error:
            out.write(f"ERROR: {error}\n")
            raise BuildFailed(image=tag, reason=error, log_path=log_path)
    info = inspect(client, tag)
    if info is None:
        raise BuildFailed(image=tag, reason="the engine reported no image", log_path=log_path)
    return info


def _follow_build(stream: Iterable[dict[str, Any]], out: Any, on_step: LineSink) -> str:
    for chunk in stream:
        if "error" in chunk:
            return str(chunk["error"]).strip()
        text = str(chunk.get("stream") or chunk.get("status") or "")
        if not text:
            continue
        out.write(text if text.endswith("\n") else text + "\n")
        for line in text.splitlines():
            if line.startswith("Step "):
                on_step(line.strip())
    return ""


def import_rootfs(
    client: docker.DockerClient, *, tarball: Path, repository: str, tag: str, changes: list[str]
) -> ImageInfo:
    """``docker import`` a root file system tarball as ``repository:tag``."""
    try:
        client.api.import_image_from_file(
            str(tarball), repository=repository, tag=tag, changes=changes
        )
    except docker.errors.APIError as exc:
        raise ImageError(
            image=f"{repository}:{tag}", reason=f"import failed: {exc.explanation}"
        ) from exc
    info = inspect(client, f"{repository}:{tag}")
    if info is None:
        raise ImageError(image=f"{repository}:{tag}", reason="import produced no image")
    return info


def list_labelled(client: docker.DockerClient, labels: Mapping[str, str]) -> list[ImageInfo]:
    """Local images carrying every one of ``labels``, newest first."""
    filters = {"label": [f"{key}={value}" for key, value in labels.items()]}
    try:
        found = client.api.images(filters=filters)
    except docker.errors.APIError as exc:
        raise InfrastructureError(f"cannot list images: {exc.explanation}") from exc
    found.sort(key=lambda item: int(item.get("Created") or 0), reverse=True)
    result = []
    for item in found:
        info = inspect(client, str(item["Id"]))
        if info is not None:
            result.append(replace(info, created_unix=int(item.get("Created") or 0)))
    return result


def remove_unused(client: docker.DockerClient, reference: str) -> bool:
    """Remove an image unless a container uses it; True when removed."""
    try:
        client.api.remove_image(reference, force=False)
    except docker.errors.APIError as exc:
        if exc.status_code in (404, 409):
            return False
        raise ImageError(image=reference, reason=f"cannot remove: {exc.explanation}") from exc
    log.info("removed unused image %s", reference)
    return True


def tag(client: docker.DockerClient, source: str, repository: str, tag_name: str) -> None:
    try:
        client.api.tag(source, repository, tag_name)
    except docker.errors.APIError as exc:
        raise ImageError(image=source, reason=f"cannot tag: {exc.explanation}") from exc


def remove(client: docker.DockerClient, reference: str) -> None:
    """Remove a local image; absent images are fine."""
    try:
        client.api.remove_image(reference, force=True)
    except docker.errors.ImageNotFound:
        return
    except docker.errors.APIError as exc:
        if exc.status_code == 404:
            return
        raise ImageError(image=reference, reason=f"cannot remove: {exc.explanation}") from exc
    log.info("removed image %s", reference)


def push(
    client: docker.DockerClient, repository: str, tag_name: str, *, auth: RegistryLogin | None
) -> str:
    """Push ``repository:tag`` and return the manifest digest the registry reported."""
    reference = f"{repository}:{tag_name}"
    try:
        stream = client.api.push(
            repository,
            tag=tag_name,
            auth_config=auth.as_auth_config() if auth else None,
            stream=True,
            decode=True,
        )
        digest = ""
        for chunk in stream:
            if "error" in chunk:
                raise ImagePullError(
                    image=reference, reason=_classify(reference, str(chunk["error"]), auth)
                )
            match = re.search(r"digest: (sha256:[0-9a-f]{64})", str(chunk.get("status", "")))
            if match:
                digest = match.group(1)
    except docker.errors.APIError as exc:
        reason = _classify(reference, str(exc.explanation or exc), auth)
        raise ImagePullError(image=reference, reason=reason) from exc
    if not digest:
        raise ImagePullError(image=reference, reason="push reported no digest")
    log.info("pushed %s (%s)", reference, digest)
    return digest


@dataclass(frozen=True, slots=True, kw_only=True)
class PullEvent:
    """One progress message of a pull: a layer's status and bytes so far (0 when unknown)."""

    layer: str
    status: str
    current: int = 0
    total: int = 0


PullSink = Callable[[PullEvent], None]


def pull(
    client: docker.DockerClient,
    repository: str,
    tag_name: str,
    *,
    auth: RegistryLogin | None,
    on_progress: PullSink | None = None,
) -> ImageInfo:
    """Pull ``repository:tag`` and return the local image (its ``repo_digests`` pin it).

    ``on_progress`` gets every layer progress message of the engine. A failed pull raises
    :class:`ImagePullError` whose ``transient`` says whether trying again may help.
    """
    reference = f"{repository}:{tag_name}"
    try:
        stream = client.api.pull(
            repository,
            tag=tag_name,
            auth_config=auth.as_auth_config() if auth else None,
            stream=True,
            decode=True,
        )
        for chunk in stream:
            if "error" in chunk:
                message = str(chunk["error"])
                raise ImagePullError(image=reference, reason=_classify(reference, message, auth),
                                     transient=_transient(message))
            if on_progress is not None and chunk.get("id"):
                detail = chunk.get("progressDetail") or {}
                on_progress(PullEvent(
                    layer=str(chunk["id"]), status=str(chunk.get("status", "")),
                    current=int(detail.get("current") or 0), total=int(detail.get("total") or 0),
                ))
    except docker.errors.APIError as exc:
        message = str(exc.explanation or exc)
        reason = _classify(reference, message, auth)
        transient = _transient(message) or (exc.status_code or 0) >= 500
        raise ImagePullError(image=reference, reason=reason, transient=transient) from exc
    except requests.exceptions.ConnectionError as exc:  # the engine's stream broke off
        raise ImagePullError(image=reference, reason=f"pull interrupted: {exc}",
                             transient=True) from exc
    info = inspect(client, reference)
    if info is None:
        raise ImagePullError(image=reference, reason="pull finished but the image is absent")
    log.info("pulled %s (%s)", reference, info.id)
    return info


_AUTH = ("unauthorized", "authentication required", "no basic auth credentials", "denied")
_NOT_FOUND = ("manifest unknown", "not found", "name unknown")
_UNREACHABLE = (
    "connection refused",
    "no such host",
    "i/o timeout",
    "dial tcp",
    "network is unreachable",
    "timeout exceeded",
    "server gave http response to https client",
)


_TRANSIENT = (
    "connection refused",
    "connection reset",
    "i/o timeout",
    "tls handshake timeout",
    "timeout exceeded",
    "network is unreachable",
    "unexpected eof",
    "503 service unavailable",
    "502 bad gateway",
    "504 gateway timeout",
    "500 internal server error",
    "429 too many requests",
    "toomanyrequests",
    "unexpected http status: 5",
)


def _transient(message: str) -> bool:
    """Whether an engine error message says that trying again may help."""
    lowered = message.lower()
    if any(word in lowered for word in _AUTH) or "server gave http response" in lowered:
        return False
    return any(word in lowered for word in _TRANSIENT)


def _classify(reference: str, message: str, auth: RegistryLogin | None) -> str:
    """An engine error message in the words an operator can act on."""
    repository, _, tag_name = reference.rpartition(":")
    registry = registry_of(repository) or "docker.io"
    lowered = message.lower()
    if any(word in lowered for word in _UNREACHABLE):
        return f"registry {registry} unreachable: {message.strip()}"
    if any(word in lowered for word in _AUTH):
        user = auth.username if auth else "anonymous"
        return f"authentication failed for {registry} (user {user}): {message.strip()}"
    if any(word in lowered for word in _NOT_FOUND):
        return f"tag {tag_name} not found in {repository}"
    return message.strip()


__all__ = [
    "BuildFailed",
    "ImageInfo",
    "PullEvent",
    "PullSink",
    "RegistryLogin",
    "build",
    "import_rootfs",
    "inspect",
    "list_labelled",
    "pull",
    "push",
    "registry_of",
    "remove",
    "remove_unused",
    "tag",
]
