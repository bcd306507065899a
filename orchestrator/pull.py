"""Team images before a match: pull each player's image, pin its digest, check its size.

:func:`resolve_team_images` never raises for a bad team image: each player gets a
:class:`ResolvedImage` whose ``error`` says what went wrong (wrong password, unknown tag,
unreachable registry, over the size limit), so the match can spawn that robot without a
controller, or forfeit a team without any valid image. The pinned reference (``repo@sha256:..``)
is what the match starts, so a tag pushed during the match changes nothing.

Before anything is pulled, the registry's manifests are read with the team's login (Basic or
Bearer token, or an ECR token; :mod:`orchestrator.registry`): an unknown tag, a refused login, an
image over the image limit or a team over its total (each layer once) fails at once, without
pulling gigabytes. Pulls that fail for a transient reason (registry unreachable, 5xx, a broken
connection) are retried with backoff and jitter; their progress goes to a
:class:`~orchestrator.console.Progress`.
"""

from __future__ import annotations

import logging
import os
from collections.abc import Mapping
from dataclasses import dataclass, replace
from pathlib import Path
from typing import TYPE_CHECKING

from orchestrator.config import COLORS, Limits, RegistryAuth, TeamConfig
from orchestrator.console import NullProgress, Progress, PullTracker
from orchestrator.engine import images as engine_images
from orchestrator.errors import ImageError, ImagePullError, ImageTooLarge, TeamImagesTooLarge
from orchestrator.image_origin import local_name_reason
from orchestrator.registry import (
    Credentials,
    RegistryClient,
    RegistryError,
    RemoteImage,
    client_for,
    inspect_remote,
    team_stored_bytes,
)
from orchestrator.retry import Backoff, retry

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
    stored_bytes: int = 0  # compressed size in the registry (0 when not read)
    pull_attempts: int = 0  # engine pulls made (1 + retries; 0 for a local image)

    @property
    def ok(self) -> bool:
        return self.error is None


PULL_BACKOFF = Backoff(attempts=4, base_s=2.0, cap_s=30.0)


def resolve_team_images(
    engine: DockerClient,
    team_config: TeamConfig,
    *,
    limits: Limits,
    environ: Mapping[str, str] | None = None,
    progress: Progress | None = None,
    backoff: Backoff = PULL_BACKOFF,
    registry_only: bool = False,
) -> dict[int, ResolvedImage]:
    """Check every player's image in its registry, then pull and pin it; see module doc.

    ``registry_only`` (official and service matches): an image name without a registry part is
    refused (:func:`local_name_refused`), so a team never runs an image that merely happens to
    be on this host (another team's, pulled for an earlier match)."""
    environ = os.environ if environ is None else environ
    limit_bytes = round(limits.image_gb * GB)
    references = list(dict.fromkeys(p.image for p in team_config.players if p.image))
    logins = _Logins(team_config.registry_auth, environ)
    failed: dict[str, ImageError] = {}
    remote: dict[str, RemoteImage] = {}
    for reference in references:
        refused = local_name_refused(reference) if registry_only else None
        if refused is not None:
            log.info("image %s: %s", reference, refused.reason)
            failed[reference] = refused
            continue
        try:
            found = _inspect(reference, logins)
        except ImageError as exc:
            log.info("image %s: %s", reference, exc.reason)
            failed[reference] = exc
            continue
        if found is None:
            continue
        remote[reference] = found
        if found.size_bytes > limit_bytes:
            failed[reference] = ImageTooLarge(
                image=reference, size_bytes=found.size_bytes, limit_bytes=limit_bytes
            )
            log.info("image %s: %s (not pulled)", reference, failed[reference].reason)
    team_limit = round(limits.team_images_gb * GB)
    team_bytes = team_stored_bytes([r for ref, r in remote.items() if ref not in failed])
    if team_bytes > team_limit:
        for reference in remote:
            failed.setdefault(reference, TeamImagesTooLarge(
                image=reference, team_bytes=team_bytes, limit_bytes=team_limit))
        log.info("team %s: images over the team limit (%.2f GB)", team_config.name,
                 team_bytes / 1e9)
    by_reference: dict[str, ResolvedImage] = {}
    for reference in references:
        stored = remote[reference].size_bytes if reference in remote else 0
        if reference in failed:
            by_reference[reference] = _failed(0, reference, failed[reference], stored)
        else:
            by_reference[reference] = _resolve_one(
                engine, reference, logins, limit_bytes,
                progress=progress or NullProgress(), backoff=backoff, stored_bytes=stored,
            )
    result: dict[int, ResolvedImage] = {}
    for player in team_config.players:
        if player.image is None:
            error = ImageError(image="(none)", reason=f"no image named for player {player.number}")
            result[player.number] = _failed(player.number, "", error)
            continue
        resolved = by_reference[player.image]
        result[player.number] = replace(resolved, number=player.number)
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
            engine, loaded.team(color), limits=loaded.game.limits, environ=environ,
            registry_only=loaded.game.registry_images,
        )
        for color in COLORS
    }
    result = GamePull(game=Path(game), teams=teams)
    log.info("pulled the images of %s: %s", game, result)
    return result


def local_name_refused(reference: str) -> ImagePullError | None:
    """The refusal of a team image named without a registry part (see
    :func:`orchestrator.image_origin.local_name_reason`), or None."""
    reason = local_name_reason(reference)
    return None if reason is None else ImagePullError(image=reference, reason=reason)


def split_reference(reference: str) -> tuple[str, str]:
    """(repository, tag) of ``repo[:tag]``; the tag defaults to ``latest``."""
    repository, sep, tag_name = reference.rpartition(":")
    if not sep or "/" in tag_name:
        return reference, "latest"
    return repository, tag_name


class _Logins:
    """A team's registry logins, made once per registry (an ECR token is asked for once)."""

    def __init__(self, auth: RegistryAuth | None, environ: Mapping[str, str]) -> None:
        self.auth = auth
        self.environ = environ
        self._engine: dict[str, engine_images.RegistryLogin | None] = {}
        self._clients: dict[str, RegistryClient] = {}

    def engine_login(self, registry: str, reference: str) -> engine_images.RegistryLogin | None:
        if registry not in self._engine:
            self._engine[registry] = _login(registry, reference, self.auth, self.environ)
        return self._engine[registry]

    def client(self, registry: str, reference: str) -> RegistryClient:
        if registry not in self._clients:
            login = self.engine_login(registry, reference)
            credentials = (
                Credentials(username=login.username, password=login.password) if login else None
            )
            self._clients[registry] = client_for(registry, credentials, environ=self.environ)
        return self._clients[registry]


def _inspect(reference: str, logins: _Logins) -> RemoteImage | None:
    """The image in its registry (None for a local or Docker Hub name, or when the registry's
    API cannot be read for another reason than the image: the pull then decides)."""
    repository, tag_name = split_reference(reference)
    registry = engine_images.registry_of(repository)
    if not registry:
        return None
    try:
        return inspect_remote(reference, logins.client(registry, reference))
    except RegistryError as exc:
        if exc.kind == "auth":
            raise ImagePullError(image=reference, reason=exc.reason) from exc
        if exc.kind in ("denied", "platform"):
            raise ImagePullError(image=reference, reason=f"{registry}: {exc.reason}") from exc
        if exc.kind == "not_found":
            raise ImagePullError(
                image=reference, reason=f"tag {tag_name} not found in {repository}"
            ) from exc
        if exc.kind == "deadline":  # a registry that answers too slowly is not pulled from
            raise ImagePullError(image=reference, reason=f"{registry}: {exc.reason}") from exc
        if exc.transient:
            raise ImagePullError(
                image=reference, reason=f"registry {registry} unreachable: {exc.reason}",
                transient=True,
            ) from exc
        log.warning("image %s: cannot read its manifest (%s); pulling it unchecked", reference,
                    exc)
        return None


def _resolve_one(
    engine: DockerClient,
    reference: str,
    logins: _Logins,
    limit_bytes: int,
    *,
    progress: Progress,
    backoff: Backoff,
    stored_bytes: int = 0,
) -> ResolvedImage:
    repository, tag_name = split_reference(reference)
    registry = engine_images.registry_of(repository)
    attempts = 0

    def pull_once(login: engine_images.RegistryLogin | None) -> engine_images.ImageInfo:
        nonlocal attempts
        attempts += 1
        task = progress.add(f"pull {reference}", unit="B")
        try:
            info = engine_images.pull(engine, repository, tag_name, auth=login,
                                      on_progress=PullTracker(task))
        except ImageError:
            task.finish("failed")
            raise
        task.finish()
        return info

    def pull(login: engine_images.RegistryLogin | None) -> engine_images.ImageInfo:
        return retry(
            lambda: pull_once(login),
            transient=lambda exc: isinstance(exc, ImagePullError) and exc.transient,
            backoff=backoff,
            what=f"pull of {reference}",
        )

    try:
        if not registry:
            info = engine_images.inspect(engine, reference)
            if info is not None:
                log.warning("image %s: local image %s, used as is (allowed only where the game "
                            "does not set registry_images)", reference, info.id)
            else:
                info = pull(None)
        else:
            info = pull(logins.engine_login(registry, reference))
    except ImageError as exc:
        log.info("image %s: %s", reference, exc.reason)
        return _failed(0, reference, exc, stored_bytes, attempts)
    digest = next((d for d in info.repo_digests if d.startswith(repository + "@")), "")
    if not digest:
        digest = info.repo_digests[0] if info.repo_digests else info.id
    error: ImageError | None = None
    if info.volumes:
        error = ImageError(image=reference, reason=(
            f"declares VOLUME {', '.join(info.volumes)}: a volume would give the robot disk "
            "space outside its caps; a robot writes to /robocup-logs and its scratch folders "
            "(/tmp, /var/tmp, /root) only: remove the VOLUME instruction (also from the base "
            "image) and push it again"))
        log.info("image %s: %s", reference, error.reason)
    elif info.size_bytes > limit_bytes:
        error = ImageTooLarge(image=reference, size_bytes=info.size_bytes, limit_bytes=limit_bytes)
        log.info("image %s: %s; removing it", reference, error.reason)
        if registry:  # a pulled copy goes; a team's local-only image is not ours to delete
            engine_images.remove(engine, reference)
    else:
        log.info("image %s: pinned %s (%.0f MB)", reference, digest, info.size_bytes / 1e6)
    return ResolvedImage(
        number=0,
        reference=reference,
        digest=digest,
        image_id=info.id,
        size_bytes=info.size_bytes,
        error=error,
        stored_bytes=stored_bytes,
        pull_attempts=attempts,
    )


def _login(
    registry: str, reference: str, auth: RegistryAuth | None, environ: Mapping[str, str]
) -> engine_images.RegistryLogin | None:
    if auth is None:
        return None
    if auth.ecr is not None:
        from orchestrator.ecr import ecr_login  # boto3, only for teams on Amazon ECR

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
    return engine_images.RegistryLogin(username=auth.username, password=password)


def _failed(
    number: int, reference: str, error: ImageError, stored_bytes: int = 0, attempts: int = 0
) -> ResolvedImage:
    return ResolvedImage(
        number=number, reference=reference, digest="", image_id="", size_bytes=0, error=error,
        stored_bytes=stored_bytes, pull_attempts=attempts,
    )


__all__ = [
    "GamePull",
    "ResolvedImage",
    "pull_game_images",
    "resolve_team_images",
    "local_name_refused",
    "split_reference",
]
