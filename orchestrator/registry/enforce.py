"""Registry size limits through the registry API (catalog, tags, manifests, delete).

The league keeps each image under ``image_limit`` and each team's images together under
``team_limit``; sizes are the stored (compressed) blobs of the manifests, and a layer shared by
several images of a team counts once in the team's total. :func:`plan_enforcement` is a pure
function of the registry's content: images over the image limit are deleted first; then, for each
team still over its limit, images in a seeded random order until the team is under. Deletion is by
manifest digest; the registry frees disk space only after its garbage collector runs
(``docker-registry garbage-collect CONFIG``).
"""

from __future__ import annotations

import logging
import random
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Literal, TypedDict

from orchestrator.registry.client import RegistryClient, union_bytes

log = logging.getLogger(__name__)


@dataclass(frozen=True, slots=True, kw_only=True)
class RegistryImage:
    """One manifest in one repository (all tags that point to it) and its stored size."""

    repository: str
    digest: str
    tags: tuple[str, ...]
    size_bytes: int  # config + layers, as stored (compressed)
    team: str
    blobs: Mapping[str, int] = field(default_factory=dict)  # digest -> bytes (config + layers)

    def blob_sizes(self) -> Mapping[str, int]:
        """The blobs this image keeps in the registry (itself as one blob when unknown)."""
        return self.blobs or {self.digest: self.size_bytes}


@dataclass(frozen=True, slots=True, kw_only=True)
class Deletion:
    image: RegistryImage
    reason: Literal["image_over_limit", "team_over_limit"]


def registry_images(client: RegistryClient, team_of: TeamRule) -> list[RegistryImage]:
    """Every (repository, manifest) in the registry with its tags, blobs and size."""
    result = []
    for repository in client.repositories():
        by_digest: dict[str, tuple[list[str], Mapping[str, int]]] = {}
        for tag_name in client.tags(repository):
            manifest = client.manifest(repository, tag_name)
            by_digest.setdefault(manifest.digest, ([], manifest.blobs))[0].append(tag_name)
        for digest, (tag_names, blobs) in sorted(by_digest.items()):
            result.append(
                RegistryImage(
                    repository=repository,
                    digest=digest,
                    tags=tuple(tag_names),
                    size_bytes=sum(blobs.values()),
                    team=team_of.team(repository),
                    blobs=dict(blobs),
                )
            )
    return result


def stored_bytes(images: Sequence[RegistryImage]) -> int:
    """What ``images`` occupy together: a layer shared by several of them counts once."""
    return union_bytes(image.blob_sizes() for image in images)


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
    """What to delete so that every image and every team is within its limit. A team's size
    counts each layer once, however many of its images share it."""
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
        rng.shuffle(kept)
        while kept and stored_bytes(kept) > team_limit_bytes:
            image = kept.pop(0)
            deletions.append(Deletion(image=image, reason="team_over_limit"))
    return deletions


class TeamUsage(TypedDict):
    images: int
    before_bytes: int
    after_bytes: int


class DeletedImage(TypedDict):
    repository: str
    digest: str
    tags: list[str]
    size_bytes: int
    team: str
    reason: str


class EnforcementReport(TypedDict):
    """What :func:`enforce` did (or, with ``dry_run``, would do)."""

    registry: str
    dry_run: bool
    seed: int
    image_limit_bytes: int
    team_limit_bytes: int
    teams: dict[str, TeamUsage]
    deleted: list[DeletedImage]


def enforce(
    client: RegistryClient,
    *,
    image_limit_bytes: int,
    team_limit_bytes: int,
    seed: int,
    team_of: TeamRule,
    dry_run: bool,
) -> EnforcementReport:
    """Apply the limits (or only plan them with ``dry_run``) and return the JSON report."""
    images = registry_images(client, team_of)
    deletions = plan_enforcement(
        images, image_limit_bytes=image_limit_bytes, team_limit_bytes=team_limit_bytes, seed=seed
    )
    if not dry_run:
        for deletion in deletions:
            client.delete(deletion.image.repository, deletion.image.digest)
    deleted_ids = {id(d.image) for d in deletions}
    teams: dict[str, TeamUsage] = {}
    for team in sorted({i.team for i in images}):
        mine = [i for i in images if i.team == team]
        teams[team] = {
            "images": len(mine),
            "before_bytes": stored_bytes(mine),
            "after_bytes": stored_bytes([i for i in mine if id(i) not in deleted_ids]),
        }
    return {
        "registry": client.url,
        "dry_run": dry_run,
        "seed": seed,
        "image_limit_bytes": image_limit_bytes,
        "team_limit_bytes": team_limit_bytes,
        "teams": teams,
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
    "RegistryImage",
    "TeamRule",
    "enforce",
    "plan_enforcement",
    "registry_images",
    "stored_bytes",
]
