"""Where a team image comes from: the registry part of its name (no Docker import here, so that
``hlvs check`` stays fast)."""

from __future__ import annotations

PROJECT_REPOSITORY = "hlvs-runner/"  # the project's own images, built on this host


def registry_of(repository: str) -> str:
    """The registry host of a repository name, or "" for a Docker Hub or local name."""
    first = repository.split("/", 1)[0]
    if "/" in repository and ("." in first or ":" in first or first == "localhost"):
        return first
    return ""


def local_name_reason(reference: str) -> str | None:
    """Why a team image named ``reference`` is refused where team images must come from a
    registry (None when it names one, or is one of the project's own ``hlvs-runner/`` images,
    such as the stub team)."""
    name_part = reference.partition("@")[0]
    repository, sep, tag = name_part.rpartition(":")
    if not sep or "/" in tag:
        repository = name_part
    if registry_of(repository) or repository.startswith(PROJECT_REPOSITORY):
        return None
    name = repository.rsplit("/", 1)[-1]
    return (f"{reference} names no registry: a team's image is pulled from its registry with "
            f"the team's login, never taken from this host; push it (docker tag {reference} "
            f"REGISTRY/TEAM/{name} && docker push REGISTRY/TEAM/{name}) and name "
            f"REGISTRY/TEAM/{name} in team_config.json, with registry_auth for a private "
            "registry")


__all__ = ["PROJECT_REPOSITORY", "local_name_reason", "registry_of"]
