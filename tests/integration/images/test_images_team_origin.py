"""A team's images come only from its registry: another team's image on this host, named
without a registry part, is refused before anything runs, with how to push it; an image that
declares a VOLUME (disk outside the robot's caps) is refused."""

from __future__ import annotations

import uuid
from pathlib import Path

import docker
import pytest

from orchestrator.config import Limits
from orchestrator.pull import local_name_refused, resolve_team_images
from tests.conftest import TEST_LABEL
from tests.integration.images.conftest import MakeImage
from tests.integration.images.test_images_pull import team

pytestmark = pytest.mark.docker


def test_another_teams_local_image_is_refused_with_how_to_push_it(
    docker_client: docker.DockerClient, make_image: MakeImage,
) -> None:
    victim = make_image(f"victim-team-{uuid.uuid4().hex[:8]}:v1", 1000)  # on this host
    repository, _, tag = victim.rpartition(":")
    resolved = resolve_team_images(docker_client, team(repository, tag, None), limits=Limits(),
                                   registry_only=True)
    for image in resolved.values():
        assert image.error is not None and image.digest == "" and image.image_id == ""
        reason = image.error.reason
        assert f"{victim} names no registry" in reason
        assert f"docker push REGISTRY/TEAM/{repository}" in reason
    # the same name where local images are allowed (a local, non-official match): played
    local = resolve_team_images(docker_client, team(repository, tag, None), limits=Limits())
    assert all(image.ok and image.image_id for image in local.values())


def test_registry_names_and_project_images_pass_the_origin_check() -> None:
    assert local_name_refused("127.0.0.1:5000/alpha/robot:v1") is None
    assert local_name_refused("registry.example.org/alpha/robot@sha256:" + "0" * 64) is None
    assert local_name_refused("hlvs-runner/stub:63c0ac3f8a3c") is None
    for bare in ("alpha-robot:v1", "alpha/robot", "ubuntu", "alpha/robot@sha256:" + "0" * 64):
        refused = local_name_refused(bare)
        assert refused is not None and "names no registry" in refused.reason, bare


def test_an_image_with_a_volume_is_refused(docker_client: docker.DockerClient,
                                           tmp_path: Path) -> None:
    tag = f"hlvs-runner-test/volume-{uuid.uuid4().hex[:8]}:v1"
    (tmp_path / "Dockerfile").write_text("FROM scratch\nVOLUME /data /more\n")
    docker_client.images.build(path=str(tmp_path), tag=tag, network_mode="none",
                               labels={TEST_LABEL: "1"}, rm=True, forcerm=True)
    try:
        repository, _, name_tag = tag.rpartition(":")
        resolved = resolve_team_images(docker_client, team(repository, name_tag, None),
                                       limits=Limits())
        for image in resolved.values():
            assert image.error is not None
            assert "declares VOLUME /data, /more" in image.error.reason
            assert "remove the VOLUME instruction" in image.error.reason
    finally:
        docker_client.images.remove(tag, force=True)
