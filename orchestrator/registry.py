"""Registry size limits through the Registry HTTP API v2 (catalog, tags, manifests, delete).

The league keeps each image under ``image_limit`` and each team's images together under
``team_limit``. :func:`plan_enforcement` is a pure function of the registry's content: images over
the image limit are deleted first; then, for each team still over its limit, images in a seeded
random order until the team is under. :class:`RegistryClient` reads and deletes by digest. The
registry frees disk space only after its garbage collector runs
(``docker-registry garbage-collect CONFIG``).
"""

from __future__ import annotations

import base64
import hashlib
import json
import logging
import random
import urllib.error
import urllib.parse
import urllib.request
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any, Literal

from orchestrator.errors import InfrastructureError

log = logging.getLogger(__name__)

MANIFEST_TYPES = (
    "application/vnd.docker.distribution.manifest.v2+json",
    "application/vnd.oci.image.manifest.v1+json",
    "application/vnd.docker.distribution.manifest.list.v2+json",
    "application/vnd.oci.image.index.v1+json",
)
_INDEX_TYPES = MANIFEST_TYPES[2:]


class RegistryError(InfrastructureError):
    """A registry request failed: ``url``, HTTP ``status`` (0 when unreachable), ``reason``."""

    def __init__(self, *, url: str, status: int, reason: str) -> None:
        self.url = url
        self.status = status
        self.reason = reason
        where = f"HTTP {status}" if status else "unreachable"
        super().__init__(f"registry request {url} failed ({where}): {reason}")


@dataclass(frozen=True, slots=True, kw_only=True)
class RegistryImage:
    """One manifest in one repository (all tags that point to it) and its stored size."""

    repository: str
    digest: str
    tags: tuple[str, ...]
    size_bytes: int  # config + layers, as stored (compressed)
    team: str


@dataclass(frozen=True, slots=True, kw_only=True)
class Deletion:
    image: RegistryImage
    reason: Literal["image_over_limit", "team_over_limit"]


class RegistryClient:
    """A small Registry API v2 client with HTTP basic authentication."""

    def __init__(
        self, url: str, *, username: str | None = None, password: str | None = None
    ) -> None:
        self.url = url.rstrip("/")
        self._auth = (
            "Basic " + base64.b64encode(f"{username}:{password or ''}".encode()).decode()
            if username
            else None
        )

    def repositories(self) -> list[str]:
        found: list[str] = []
        path: str | None = "/v2/_catalog?n=100"
        while path:
            body, headers = self._request("GET", path)
            found.extend(json.loads(body).get("repositories") or [])
            path = _next_link(headers.get("Link", ""))
        return sorted(found)

    def tags(self, repository: str) -> list[str]:
        body, _ = self._request("GET", f"/v2/{repository}/tags/list")
        return sorted(json.loads(body).get("tags") or [])

    def manifest(self, repository: str, reference: str) -> tuple[str, int]:
        """(digest, size in bytes) of ``repository:reference``; an index sums its images."""
        body, headers = self._request(
            "GET",
            f"/v2/{repository}/manifests/{reference}",
            accept=", ".join(MANIFEST_TYPES),
        )
        computed = f"sha256:{hashlib.sha256(body).hexdigest()}"
        digest = headers.get("Docker-Content-Digest") or computed
        document = json.loads(body)
        if document.get("mediaType") in _INDEX_TYPES or "manifests" in document:
            size = sum(self.manifest(repository, m["digest"])[1] for m in document["manifests"])
        else:
            size = int(document.get("config", {}).get("size", 0)) + sum(
                int(layer.get("size", 0)) for layer in document.get("layers", [])
            )
        return digest, size

    def delete(self, repository: str, digest: str) -> None:
        self._request("DELETE", f"/v2/{repository}/manifests/{digest}")
        log.info("registry %s: deleted %s@%s", self.url, repository, digest)

    def images(self, team_of: TeamRule) -> list[RegistryImage]:
        """Every (repository, manifest) in the registry with its tags and size."""
        result = []
        for repository in self.repositories():
            by_digest: dict[str, tuple[list[str], int]] = {}
            for tag_name in self.tags(repository):
                digest, size = self.manifest(repository, tag_name)
                by_digest.setdefault(digest, ([], size))[0].append(tag_name)
            for digest, (tag_names, size) in sorted(by_digest.items()):
                result.append(
                    RegistryImage(
                        repository=repository,
                        digest=digest,
                        tags=tuple(tag_names),
                        size_bytes=size,
                        team=team_of.team(repository),
                    )
                )
        return result

    def _request(
        self, method: str, path: str, *, accept: str | None = None
    ) -> tuple[bytes, Mapping[str, str]]:
        url = self.url + path
        request = urllib.request.Request(url, method=method)
        if self._auth:
            request.add_header("Authorization", self._auth)
        if accept:
            request.add_header("Accept", accept)
        try:
            with urllib.request.urlopen(request, timeout=30) as response:
                return response.read(), dict(response.headers.items())
        except urllib.error.HTTPError as exc:
            detail = exc.read().decode(errors="replace").strip()[:300]
            if exc.code == 401:
                detail = "authentication failed (check --user and --password)"
            elif exc.code == 405 and method == "DELETE":
                detail = "deletion is disabled on this registry (storage: delete: enabled: true)"
            raise RegistryError(url=url, status=exc.code, reason=detail) from exc
        except (urllib.error.URLError, OSError) as exc:
            reason = getattr(exc, "reason", exc)
            raise RegistryError(url=url, status=0, reason=str(reason)) from exc


def _next_link(header: str) -> str | None:
    """The path of a ``Link: </v2/_catalog?last=x&n=100>; rel="next"`` header."""
    if 'rel="next"' not in header:
        return None
    target = header.split(";", 1)[0].strip().strip("<>")
    parsed = urllib.parse.urlsplit(target)
    return parsed.path + ("?" + parsed.query if parsed.query else "")


@dataclass(frozen=True, slots=True)
class TeamRule:
    """Which team a repository belongs to: the first ``prefix=team`` rule that matches, else the
    first path component (``bitbots/robot`` -> ``bitbots``)."""

    prefixes: tuple[tuple[str, str], ...] = ()

    @classmethod
    def parse(cls, rules: Sequence[str]) -> TeamRule:
        pairs = []
        for rule in rules:
            prefix, sep, team = rule.partition("=")
            if not sep or not prefix or not team:
                raise ValueError(f"--team-of {rule!r}: expected PREFIX=TEAM")
            pairs.append((prefix, team))
        return cls(tuple(pairs))

    def team(self, repository: str) -> str:
        for prefix, team in self.prefixes:
            if repository.startswith(prefix):
                return team
        return repository.split("/", 1)[0]


def plan_enforcement(
    images: Sequence[RegistryImage],
    *,
    image_limit_bytes: int,
    team_limit_bytes: int,
    seed: int,
) -> list[Deletion]:
    """What to delete so that every image and every team is within its limit."""
    deletions = [
        Deletion(image=i, reason="image_over_limit")
        for i in images
        if i.size_bytes > image_limit_bytes
    ]
    removed = {id(d.image) for d in deletions}
    rng = random.Random(seed)
    for team in sorted({i.team for i in images}):
        kept = sorted(
            (i for i in images if i.team == team and id(i) not in removed),
            key=lambda i: (i.repository, i.digest),
        )
        total = sum(i.size_bytes for i in kept)
        rng.shuffle(kept)
        for image in kept:
            if total <= team_limit_bytes:
                break
            deletions.append(Deletion(image=image, reason="team_over_limit"))
            total -= image.size_bytes
    return deletions


def enforce(
    client: RegistryClient,
    *,
    image_limit_bytes: int,
    team_limit_bytes: int,
    seed: int,
    team_of: TeamRule,
    dry_run: bool,
) -> dict[str, Any]:
    """Apply the limits (or only plan them with ``dry_run``) and return the JSON report."""
    images = client.images(team_of)
    deletions = plan_enforcement(
        images, image_limit_bytes=image_limit_bytes, team_limit_bytes=team_limit_bytes, seed=seed
    )
    if not dry_run:
        for deletion in deletions:
            client.delete(deletion.image.repository, deletion.image.digest)
    deleted_ids = {id(d.image) for d in deletions}
    teams: dict[str, dict[str, int]] = {}
    for image in images:
        entry = teams.setdefault(image.team, {"images": 0, "before_bytes": 0, "after_bytes": 0})
        entry["images"] += 1
        entry["before_bytes"] += image.size_bytes
        if id(image) not in deleted_ids:
            entry["after_bytes"] += image.size_bytes
    return {
        "registry": client.url,
        "dry_run": dry_run,
        "seed": seed,
        "image_limit_bytes": image_limit_bytes,
        "team_limit_bytes": team_limit_bytes,
        "teams": dict(sorted(teams.items())),
        "deleted": [
            {
                "repository": d.image.repository,
                "digest": d.image.digest,
                "tags": list(d.image.tags),
                "size_bytes": d.image.size_bytes,
                "team": d.image.team,
                "reason": d.reason,
            }
            for d in deletions
        ],
    }


__all__ = [
    "Deletion",
    "RegistryClient",
    "RegistryError",
    "RegistryImage",
    "TeamRule",
    "enforce",
    "plan_enforcement",
]
