"""Registry access as teams' registries really are: the distribution registry with token auth
(a token service on loopback) and with Basic auth. Pull, paginated tag lists, sizes with shared
layers counted once per team, size enforcement, and a pull retried after transient failures."""

from __future__ import annotations

import io
import json
import os
import tarfile
from pathlib import Path

import docker
import pytest

from hlvs.cli import main
from orchestrator.config import Limits, PlayerConfig, RegistryAuth, StartingPose, TeamConfig
from orchestrator.config.model import EcrAuth
from orchestrator.errors import ImagePullError, TeamImagesTooLarge
from orchestrator.pull import resolve_team_images
from orchestrator.registry import Credentials, RegistryClient, RegistryError
from orchestrator.retry import Backoff
from tests.conftest import TEST_LABEL
from tests.integration.images.conftest import FlakyProxy, MakeImage, Registry, push

pytestmark = pytest.mark.docker

POSE = StartingPose(translation=(-1.0, -3.2, 0.4), rotation=(0.0, 0.0, 1.0, 1.57))
KB = 1000
FAST = Backoff(attempts=4, base_s=0.2, cap_s=1.0)


def team(images: list[str], auth: RegistryAuth | None) -> TeamConfig:
    """A team whose player n uses images[n-1] (``repository:tag``)."""
    return TeamConfig(
        source=Path("team_config.json"),
        name="Alpha",
        image=None,
        registry_auth=auth,
        players=tuple(
            PlayerConfig(
                number=n, half_time_pose=POSE, reentry_pose=POSE, shootout_pose=POSE,
                goalkeeper_pose=POSE, model="kid-default",
                image_repository=reference.rpartition(":")[0],
                docker_tag=reference.rpartition(":")[2],
            )
            for n, reference in enumerate(images, start=1)
        ),
    )


def client(registry: Registry, user: str = "janitor", **kwargs: object) -> RegistryClient:
    credentials = Credentials(username=user, password=registry.users[user])
    return RegistryClient(registry.url, credentials=credentials, **kwargs)  # type: ignore[arg-type]


def layered_image(
    docker_client: docker.DockerClient, reference: str, base: str, own_bytes: int
) -> str:
    """An image FROM ``base`` with one more layer of ``own_bytes`` random bytes."""
    context = io.BytesIO()
    with tarfile.open(fileobj=context, mode="w") as tar:
        dockerfile = f"FROM {base}\nCOPY own.bin /own.bin\nLABEL {TEST_LABEL}=1\n".encode()
        for name, data in (("Dockerfile", dockerfile), ("own.bin", os.urandom(own_bytes))):
            info = tarfile.TarInfo(name)
            info.size = len(data)
            tar.addfile(info, io.BytesIO(data))
    context.seek(0)
    docker_client.images.build(fileobj=context, custom_context=True, tag=reference,
                               network_mode="none", rm=True, forcerm=True)
    return reference


def test_pull_tags_and_sizes_with_token_and_basic_auth(
    any_registry: Registry, docker_client: docker.DockerClient, make_image: MakeImage
) -> None:
    registry = any_registry
    repository = f"{registry.host}/alpha/robot"
    make_image(f"{repository}:v1", 20 * KB)
    pushed = push(docker_client, f"{repository}:v1", "alpha", registry.users["alpha"])
    for n in range(2, 6):
        docker_client.images.get(f"{repository}:v1").tag(repository, f"v{n}")
        push(docker_client, f"{repository}:v{n}", "alpha", registry.users["alpha"])
    for n in range(1, 6):
        docker_client.images.remove(f"{repository}:v{n}")

    # Tags over three pages of two.
    paged = client(registry, "alpha", page_size=2)
    assert paged.tags("alpha/robot") == ["v1", "v2", "v3", "v4", "v5"]
    manifest = paged.manifest("alpha/robot", "v1")
    assert manifest.digest == pushed and manifest.size_bytes > 20 * KB
    if registry.auth == "token":
        assert registry.issuer is not None
        scopes = [s for r in registry.issuer.requests if r["agent"].startswith("hlvs")
                  for s in r["scopes"]]
        assert scopes == ["repository:alpha/robot:pull"], "one token, cached, for every page"
        assert paged.token_requests == 1

    resolved = resolve_team_images(
        docker_client, team([f"{repository}:v3"], alpha_login(registry)), limits=Limits(),
        backoff=FAST,
    )
    assert resolved[1].error is None, resolved[1].error
    assert resolved[1].digest == f"{repository}@{pushed}"
    assert resolved[1].stored_bytes == manifest.size_bytes

    other_team = resolve_team_images(
        docker_client, team([f"{repository}:v1"], RegistryAuth(username="beta",
                                                               password=registry.users["beta"])),
        limits=Limits(), backoff=FAST,
    )
    error = other_team[1].error
    if registry.auth == "token":  # beta logs in, but its token grants nothing on alpha/
        assert isinstance(error, ImagePullError)
        assert "authentication failed for" in error.reason and "(user beta)" in error.reason
    else:  # htpasswd knows no rights per repository: every user may read everything
        assert error is None

    wrong = resolve_team_images(
        docker_client, team([f"{repository}:v1"], alpha_login(registry, "wrong")),
        limits=Limits(), backoff=FAST,
    )
    assert isinstance(wrong[1].error, ImagePullError)
    assert wrong[1].error.reason.startswith(
        f"authentication failed for {registry.host} (user alpha)"
    )


def alpha_login(registry: Registry, password: str | None = None) -> RegistryAuth:
    return RegistryAuth(username="alpha", password=password or registry.users["alpha"])


def test_catalog_pages_and_token_refresh(
    token_registry: Registry, docker_client: docker.DockerClient, make_image: MakeImage
) -> None:
    registry = token_registry
    assert registry.issuer is not None
    for name in ("alpha/a", "alpha/b", "alpha/c"):
        make_image(f"{registry.host}/{name}:v1", KB)
        push(docker_client, f"{registry.host}/{name}:v1", "alpha", registry.users["alpha"])
    now = [0.0]
    janitor = client(registry, page_size=1, clock=lambda: now[0])
    assert janitor.repositories() == ["alpha/a", "alpha/b", "alpha/c"]
    assert janitor.token_requests == 1
    janitor.tags("alpha/a")
    assert janitor.token_requests == 2  # another scope, another token
    janitor.tags("alpha/a")
    assert janitor.token_requests == 2  # cached
    now[0] += registry.issuer.expires_in_s  # past its lifetime: fetched again
    janitor.tags("alpha/a")
    assert janitor.token_requests == 3

    anonymous = RegistryClient(registry.url)
    with pytest.raises(RegistryError) as refused:
        anonymous.tags("alpha/a")
    assert refused.value.kind == "auth" and "(user anonymous)" in refused.value.reason


def test_team_size_counts_shared_layers_once(
    any_registry: Registry, docker_client: docker.DockerClient, make_image: MakeImage
) -> None:
    registry = any_registry
    base = make_image(f"{registry.host}/alpha/base:v1", 100 * KB)
    first = layered_image(docker_client, f"{registry.host}/alpha/striker:v1", base, 10 * KB)
    second = layered_image(docker_client, f"{registry.host}/alpha/goalie:v1", base, 10 * KB)
    for reference in (first, second):
        push(docker_client, reference, "alpha", registry.users["alpha"])
        docker_client.images.remove(reference)
    janitor = client(registry)
    striker = janitor.manifest("alpha/striker", "v1")
    goalie = janitor.manifest("alpha/goalie", "v1")
    shared = set(striker.blobs) & set(goalie.blobs)
    assert shared, "both images share the base layer"
    together = sum({**striker.blobs, **goalie.blobs}.values())
    assert together < striker.size_bytes + goalie.size_bytes

    # A team limit between "each layer once" and "each image counted whole": the team fits.
    limit_gb = (together + (striker.size_bytes + goalie.size_bytes - together) / 2) / 1e9
    fits = resolve_team_images(
        docker_client, team([first, second], alpha_login(registry)),
        limits=Limits(team_images_gb=limit_gb), backoff=FAST,
    )
    assert all(image.error is None for image in fits.values()), fits
    # Below "each layer once": refused before any pull.
    docker_client.images.remove(first)
    docker_client.images.remove(second)
    over = resolve_team_images(
        docker_client, team([first, second], alpha_login(registry)),
        limits=Limits(team_images_gb=(together - 1) / 1e9), backoff=FAST,
    )
    assert all(isinstance(image.error, TeamImagesTooLarge) for image in over.values())
    assert over[1].error is not None and over[1].error.team_bytes == together  # type: ignore[attr-defined]
    assert all(image.pull_attempts == 0 for image in over.values())


def test_enforce_with_token_auth_counts_shared_layers_once(
    token_registry: Registry, docker_client: docker.DockerClient, make_image: MakeImage,
    capsys: pytest.CaptureFixture[str],
) -> None:
    registry = token_registry
    base = make_image(f"{registry.host}/alpha/base:v1", 100 * KB)
    for name in ("striker", "goalie"):
        reference = layered_image(docker_client, f"{registry.host}/alpha/{name}:v1", base, 10 * KB)
        push(docker_client, reference, "alpha", registry.users["alpha"])
    push(docker_client, base, "alpha", registry.users["alpha"])
    janitor = client(registry)
    sizes = {r: janitor.manifest(r, "v1") for r in ("alpha/base", "alpha/striker", "alpha/goalie")}
    union = sum({k: v for m in sizes.values() for k, v in m.blobs.items()}.values())
    whole = sum(m.size_bytes for m in sizes.values())
    assert union < whole

    code = main(["registry", "enforce", "--url", registry.url, "--user", "janitor",
                 "--password", registry.users["janitor"], "--team-limit-gb", str(union / 1e9),
                 "--seed", "1", "--json"])  # fmt: skip
    assert code == 0
    report = json.loads(capsys.readouterr().out)
    assert report["deleted"] == [], "the team is within its limit when each layer counts once"
    assert report["teams"]["alpha"]["before_bytes"] == union

    code = main(["registry", "enforce", "--url", registry.url, "--user", "janitor",
                 "--password", registry.users["janitor"], "--team-limit-gb",
                 str((union - 1) / 1e9), "--seed", "1", "--json"])  # fmt: skip
    assert code == 0
    report = json.loads(capsys.readouterr().out)
    assert report["deleted"] and report["teams"]["alpha"]["after_bytes"] <= union - 1
    left = {r: janitor.tags(r) for r in janitor.repositories()}
    assert sum(1 for tags in left.values() if tags) == 3 - len(report["deleted"])


def test_ecr_token_logs_in_to_the_registry(
    registry: Registry, docker_client: docker.DockerClient, make_image: MakeImage,
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """The team file names ECR; the token comes from the ECR API (moto stands in for AWS, the
    registry is real) and logs in to both the registry API and the engine's pull."""
    moto = pytest.importorskip("moto")
    for name in ("AWS_ENDPOINT_URL", "AWS_PROFILE", "AWS_CONFIG_FILE"):
        monkeypatch.delenv(name, raising=False)
    make_image(f"{registry.host}/aws/robot:v1", 5 * KB)
    pushed = push(docker_client, f"{registry.host}/aws/robot:v1", "AWS", registry.users["AWS"])
    docker_client.images.remove(f"{registry.host}/aws/robot:v1")
    auth = RegistryAuth(ecr=EcrAuth(region="us-east-1", access_id="id", access_secret="secret"))
    with moto.mock_aws():
        resolved = resolve_team_images(
            docker_client, team([f"{registry.host}/aws/robot:v1"], auth), limits=Limits(),
            backoff=FAST,
        )
    assert resolved[1].error is None, resolved[1].error
    assert resolved[1].digest == f"{registry.host}/aws/robot@{pushed}"
    assert resolved[1].stored_bytes > 5 * KB


def test_pull_that_fails_twice_then_succeeds(
    registry: Registry, flaky_proxy: FlakyProxy, docker_client: docker.DockerClient,
    make_image: MakeImage,
) -> None:
    make_image(f"{registry.host}/alpha/robot:v1", 10 * KB)
    pushed = push(docker_client, f"{registry.host}/alpha/robot:v1", "alpha",
                  registry.users["alpha"])
    through_proxy = f"{flaky_proxy.host}/alpha/robot:v1"
    try:
        resolved = resolve_team_images(
            docker_client, team([through_proxy], alpha_login(registry)), limits=Limits(),
            backoff=FAST,
        )
    finally:
        try:
            docker_client.images.remove(through_proxy)
        except docker.errors.APIError:
            pass
    assert resolved[1].error is None, resolved[1].error
    assert resolved[1].pull_attempts == 3
    assert resolved[1].digest == f"{flaky_proxy.host}/alpha/robot@{pushed}"
    assert flaky_proxy.pulls == 3
    assert len([s for s in flaky_proxy.seen if s[2] == 503]) >= 2
    assert any(status == 200 and "/manifests/" in path for _, path, status in flaky_proxy.seen)


def test_an_index_gives_the_image_of_the_machine_platform(
    registry: Registry, docker_client: docker.DockerClient, make_image: MakeImage
) -> None:
    """A multi-platform tag (an OCI index) resolves to its linux/amd64 image; its size is that
    image's, and a platform it lacks is named in the error."""
    import base64
    import urllib.request

    reference = make_image(f"{registry.host}/alpha/multi:single", 8 * KB)
    push(docker_client, reference, "alpha", registry.users["alpha"])
    janitor = client(registry)
    single = janitor.manifest("alpha/multi", "single")
    raw = urllib.request.Request(f"{registry.url}/v2/alpha/multi/manifests/single", headers={
        "Accept": "application/vnd.docker.distribution.manifest.v2+json",
        "Authorization": "Basic " + base64.b64encode(
            f"alpha:{registry.users['alpha']}".encode()).decode()})
    with urllib.request.urlopen(raw) as answer:
        body = answer.read()
        media_type = answer.headers["Content-Type"]
    index = {
        "schemaVersion": 2,
        "mediaType": "application/vnd.oci.image.index.v1+json",
        "manifests": [
            {"mediaType": media_type, "digest": single.digest, "size": len(body),
             "platform": {"os": "linux", "architecture": arch}}
            for arch in ("arm64", "amd64")
        ],
    }
    put = urllib.request.Request(
        f"{registry.url}/v2/alpha/multi/manifests/v1", data=json.dumps(index).encode(),
        method="PUT", headers={"Content-Type": "application/vnd.oci.image.index.v1+json",
                               "Authorization": raw.get_header("Authorization")})
    with urllib.request.urlopen(put) as answer:
        assert answer.status == 201

    chosen = janitor.image("alpha/multi", "v1")
    assert chosen.digest == single.digest and chosen.size_bytes == single.size_bytes
    assert janitor.manifest("alpha/multi", "v1").blobs == single.blobs  # each blob once
    with pytest.raises(RegistryError) as missing:
        janitor.image("alpha/multi", "v1", platform="linux/s390x")
    assert missing.value.kind == "platform" and "linux/s390x" in missing.value.reason
