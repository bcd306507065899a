"""Our labels prove nothing: a container started outside the runner from an image that has the
runner's labels baked in survives ``hlvs cleanup --match`` (it is not in the runner's records),
while what the runner created for that match id goes."""

from __future__ import annotations

import io
import json
import os
import subprocess
import sys
import tarfile
import uuid

import docker
import pytest

from orchestrator.engine import LABEL_MATCH, LABEL_PROJECT, LABEL_ROLE
from orchestrator.engine.containers import DockerRuntime
from orchestrator.match.ownership import LABEL_RUN
from orchestrator.runtime.port import ContainerRequest
from tests.conftest import TEST_LABEL
from tests.integration.attack.conftest import REPO

pytestmark = [pytest.mark.docker]


def test_cleanup_leaves_a_foreign_container_that_carries_our_labels(
    docker_client: docker.DockerClient, project_images: dict[str, str],
) -> None:
    match_id = f"labels-{uuid.uuid4().hex[:8]}"
    dockerfile = (f"FROM {project_images['team-base']}\n"
                  f'LABEL {LABEL_PROJECT}="1" {LABEL_MATCH}="{match_id}" {LABEL_ROLE}="robot" '
                  f'{LABEL_RUN}="guessed" {TEST_LABEL}="1"\n').encode()
    buffer = io.BytesIO()
    with tarfile.open(fileobj=buffer, mode="w") as tar:
        info = tarfile.TarInfo("Dockerfile")
        info.size = len(dockerfile)
        tar.addfile(info, io.BytesIO(dockerfile))
    buffer.seek(0)
    tag = f"hlvs-runner-test/labelled:{match_id}"
    docker_client.images.build(fileobj=buffer, custom_context=True, tag=tag,
                               network_mode="none", rm=True, forcerm=True)
    foreign = docker_client.containers.run(tag, ["sleep", "300"], detach=True,
                                           name=f"{match_id}-foreign", network_mode="none")
    runtime = DockerRuntime(docker_client)
    ours = runtime.create_container(ContainerRequest(
        name=f"hlvs-{match_id}-red-1", image=tag, command=("sleep", "300"),
        labels={LABEL_PROJECT: "1", LABEL_MATCH: match_id, LABEL_ROLE: "robot",
                TEST_LABEL: "1"}))
    try:
        done = subprocess.run([sys.executable, "-m", "hlvs", "cleanup", "--match",
                               match_id], capture_output=True, text=True, timeout=120, cwd=REPO,
                              env={**os.environ, "PYTHONPATH": str(REPO)}, check=False)
        assert done.returncode == 0, done.stderr[-2000:]
        report = json.loads(done.stdout)
        assert report["containers"] == [f"hlvs-{match_id}-red-1"]
        assert any(f"{match_id}-foreign" in s and "did not create it" in s
                   for s in report["skipped"]), report
        foreign.reload()
        assert foreign.status == "running"
        with pytest.raises(docker.errors.NotFound):
            docker_client.containers.get(ours)
    finally:
        foreign.remove(force=True)
        docker_client.images.remove(tag, force=True)
