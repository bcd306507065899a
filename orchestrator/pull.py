"""Team images before a match: pull each player's image, pin its digest, check its size.

:func:`resolve_team_images` never raises for a bad team image: each player gets a
:class:`ResolvedImage` whose ``error`` says what went wrong (wrong password, unknown tag,
unreachable registry, over the size limit), so the match can spawn that robot without a
controller, or forfeit a team without any valid image. The pinned reference (``repo@sha256:..``)
is what the match starts, so a tag pushed during the match changes nothing.
"""

from __future__ import annotations

import logging
import os
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

from orchestrator.config import COLORS, Limits, RegistryAuth, TeamConfig
from orchestrator.ecr import ecr_login
from orchestrator.engine import images as engine_images
from orchestrator.errors import ImageError, ImagePullError, ImageTooLarge

if TYPE_CHECKING:
    from docker import DockerClient

log = logging.getLogger(__name__)

GB = 1_000_000_000


@dataclass(frozen=True, slots=True, kw_only=True)
class ResolvedImage:
    """One player's image: what the team asked for and what the match will start."""

    number: int
    reference: str  # as in the team config: repository:tag ("" when none was named)
    digest: str  # pinned: repository@sha256:... (the image id for a local-only image)
    image_id: str
    size_bytes: int
    error: ImageError | None = None

    @property
    def ok(self) -> bool:
        return self.error is None


def resolve_team_images(
    engine: DockerClient,
    team_config: TeamConfig,
    *,
    limits: Limits,
    environ: Mapping[str, str] | None = None,
) -> dict[int, ResolvedImage]:
    """Pull every player's image (once per distinct reference) and pin it; see module doc."""
    environ = os.environ if environ is None else environ
    limit_bytes = int(limits.image_gb * GB)
    by_reference: dict[str, ResolvedImage] = {}
    result: dict[int, ResolvedImage] = {}
    for player in team_config.players:
        reference = player.image
        if reference is None:
            error = ImageError(image="(none)", reason=f"no image named for player {player.number}")
            result[player.number] = _failed(player.number, "", error)
            continue
        if reference not in by_reference:
            by_reference[reference] = _resolve_one(
                engine, reference, team_config.registry_auth, environ, limit_bytes
            )
        resolved = by_reference[reference]
        result[player.number] = ResolvedImage(
            number=player.number,
            reference=resolved.reference,
            digest=resolved.digest,
            image_id=resolved.image_id,
            size_bytes=resolved.size_bytes,
            error=resolved.error,
        )
    return result


@dataclass(frozen=True, slots=True, kw_only=True)
class GamePull:
    """Both teams' images of one game, pulled ahead of the match (the scheduler's pull step)."""

    game: Path
    teams: Mapping[str, Mapping[int, ResolvedImage]]  # "red" / "blue" -> player -> image

    @property
    def ok(self) -> bool:
        return all(image.ok for team in self.teams.values() for image in team.values())

    def __str__(self) -> str:
        parts = []
        for color, team in self.teams.items():
            pinned = sum(1 for image in team.values() if image.ok)
            errors = sorted({str(image.error) for image in team.values() if image.error})
            text = f"{color}: {pinned}/{len(team)} images pinned"
            parts.append(text + (f" ({'; '.join(errors)})" if errors else ""))
        return "; ".join(parts)


def pull_game_images(
    game: Path | str,
    *,
    engine: DockerClient | None = None,
    environ: Mapping[str, str] | None = None,
) -> GamePull:
    """Pull and pin both teams' images of ``game`` (a game.json); bad images are reported, not
    raised, since the match still plays (robots without a valid image spawn without a controller).
    """
    from orchestrator.config import load_game
    from orchestrator.engine import connect

    loaded = load_game(game, images_required=False)
    engine = engine or connect()
    teams: dict[str, Mapping[int, ResolvedImage]] = {
        color: resolve_team_images(
            engine, loaded.team(color), limits=loaded.game.limits, environ=environ
        )
        for color in COLORS
    }
    result = GamePull(game=Path(game), teams=teams)
    log.info("pulled the images of %s: %s", game, result)
    return result


def split_reference(reference: str) -> tuple[str, str]:
    """(repository, tag) of ``repo[:tag]``; the tag defaults to ``latest``."""
    repository, sep, tag_name = reference.rpartition(":")
    if not sep or "/" in tag_name:
        return reference, "latest"
    return repository, tag_name


def _resolve_one(
    engine: DockerClient,
    reference: str,
    auth: RegistryAuth | None,
    environ: Mapping[str, str],
    limit_bytes: int,
) -> ResolvedImage:
    repository, tag_name = split_reference(reference)
    registry = engine_images.registry_of(repository)
    try:
        if not registry:
            info = engine_images.inspect(engine, reference)
            if info is not None:
                log.info("image %s: local image %s, used as is", reference, info.id)
            else:
                info = engine_images.pull(engine, repository, tag_name, auth=None)
        else:
            login = _login(registry, reference, auth, environ)
            info = engine_images.pull(engine, repository, tag_name, auth=login)
    except ImageError as exc:
        log.info("image %s: %s", reference, exc.reason)
        return _failed(0, reference, exc)
    digest = next((d for d in info.repo_digests if d.startswith(repository + "@")), "")
    if not digest:
        digest = info.repo_digests[0] if info.repo_digests else info.id
    if info.size_bytes > limit_bytes:
        error = ImageTooLarge(image=reference, size_bytes=info.size_bytes, limit_bytes=limit_bytes)
        log.info("image %s: %s; removing it", reference, error.reason)
        if registry:  # a pulled copy goes; a team's local-only image is not ours to delete
            engine_images.remove(engine, reference)
        return ResolvedImage(
            number=0,
            reference=reference,
            digest=digest,
            image_id=info.id,
            size_bytes=info.size_bytes,
            error=error,
        )
    log.info("image %s: pinned %s (%.0f MB)", reference, digest, info.size_bytes / 1e6)
    return ResolvedImage(
        number=0,
        reference=reference,
        digest=digest,
        image_id=info.id,
        size_bytes=info.size_bytes,
    )


def _login(
    registry: str, reference: str, auth: RegistryAuth | None, environ: Mapping[str, str]
) -> engine_images.RegistryAuth | None:
    if auth is None:
        return None
    if auth.ecr is not None:
        return ecr_login(
            registry=registry,
            region=auth.ecr.region,
            access_id=auth.ecr.access_id,
            access_secret=auth.ecr.access_secret,
            image=reference,
        )
    if auth.username is None:
        return None
    password = auth.password_from(environ)
    if password is None:
        raise ImagePullError(
            image=reference,
            reason=f"authentication failed for {registry} (user {auth.username}): "
            f"environment variable {auth.password_env} is not set",
        )
    return engine_images.RegistryAuth(username=auth.username, password=password)


def _failed(number: int, reference: str, error: ImageError) -> ResolvedImage:
    return ResolvedImage(
        number=number, reference=reference, digest="", image_id="", size_bytes=0, error=error
    )


__all__ = [
    "GamePull",
    "ResolvedImage",
    "pull_game_images",
    "resolve_team_images",
    "split_reference",
]
