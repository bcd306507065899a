"""``hlvs registry enforce`` against a real registry with tiny images and tiny limits."""

from __future__ import annotations

import json
from typing import Any

import docker
import pytest

from hlvs.cli import main
from orchestrator.registry import RegistryClient
from tests.integration.images.conftest import MakeImage, Registry, push

pytestmark = pytest.mark.docker

KB = 1000


def fill(registry: Registry, client: docker.DockerClient, make_image: MakeImage) -> None:
    """alpha: a 200 KB image and two 50 KB ones; beta: one 30 KB image."""
    for reference, size in (
        ("alpha/huge:v1", 200 * KB),
        ("alpha/one:v1", 50 * KB),
        ("alpha/two:v1", 50 * KB),
        ("beta/robot:v1", 30 * KB),
    ):
        full = make_image(f"{registry.host}/{reference}", size)
        team = reference.split("/")[0]
        push(client, full, team, registry.users[team])


def enforce(registry: Registry, capsys: pytest.CaptureFixture[str], *extra: str) -> dict[str, Any]:
    code = main(
        [
            "registry",
            "enforce",
            "--url",
            registry.url,
            "--user",
            "janitor",
            "--password",
            registry.users["janitor"],
            "--image-limit-gb",
            str(150 * KB / 1e9),
            "--team-limit-gb",
            str(70 * KB / 1e9),
            "--seed",
            "7",
            "--json",
            *extra,
        ]
    )
    assert code == 0
    return dict(json.loads(capsys.readouterr().out))


def tags(registry: Registry) -> dict[str, list[str]]:
    client = RegistryClient(registry.url, username="janitor", password=registry.users["janitor"])
    return {repo: client.tags(repo) for repo in client.repositories()}


def test_enforce_deletes_oversize_then_random_until_team_is_under(
    registry: Registry,
    docker_client: docker.DockerClient,
    make_image: MakeImage,
    capsys: pytest.CaptureFixture[str],
) -> None:
    fill(registry, docker_client, make_image)

    planned = enforce(registry, capsys, "--dry-run")
    assert tags(registry) == {
        "alpha/huge": ["v1"],
        "alpha/one": ["v1"],
        "alpha/two": ["v1"],
        "beta/robot": ["v1"],
    }, "a dry run deletes nothing"
    assert planned["dry_run"] is True

    report = enforce(registry, capsys)

    assert [(d["repository"], d["reason"]) for d in report["deleted"]][0] == (
        "alpha/huge",
        "image_over_limit",
    )
    randoms = [d for d in report["deleted"] if d["reason"] == "team_over_limit"]
    assert len(randoms) == 1 and randoms[0]["repository"] in ("alpha/one", "alpha/two")
    assert report["deleted"] == planned["deleted"], "the same seed plans the same deletions"
    assert report["teams"]["alpha"]["after_bytes"] <= 70 * KB < report["teams"]["alpha"][
        "before_bytes"
    ]
    assert report["teams"]["beta"]["after_bytes"] == report["teams"]["beta"]["before_bytes"]
    left = {repo: t for repo, t in tags(registry).items() if t}
    survivor = "alpha/two" if randoms[0]["repository"] == "alpha/one" else "alpha/one"
    assert left == {survivor: ["v1"], "beta/robot": ["v1"]}

    assert enforce(registry, capsys)["deleted"] == [], "a second run has nothing to do"


def test_enforce_with_wrong_password_fails_with_the_url(
    registry: Registry, capsys: pytest.CaptureFixture[str]
) -> None:
    code = main(["registry", "enforce", "--url", registry.url, "--user", "janitor",
                 "--password", "wrong", "--json"])  # fmt: skip
    assert code == 3
    err = capsys.readouterr().err
    assert f"registry request {registry.url}/v2/_catalog" in err
    assert "authentication failed" in err
