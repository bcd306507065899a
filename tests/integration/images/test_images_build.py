"""Project images are content-tagged: asking again for unchanged inputs builds nothing."""

from __future__ import annotations

import io
from pathlib import Path

import docker
import pytest

from orchestrator.console import PlainProgress, StepTracker
from orchestrator.engine import images as engine_images
from orchestrator.project_images import LABEL_CONTENT, LABEL_IMAGE, ensure_image, project_image
from tests.conftest import TEST_LABEL
from tests.integration.images.conftest import MakeImage

pytestmark = pytest.mark.docker

# The team base carries the robot client library and what it needs, not the simulator server.
CHECK = (
    "import importlib.util as u, numpy, google.protobuf, robot.client, sys; "
    "print(sys.version_info[:2], u.find_spec('simulator') is None, u.find_spec('mujoco') is None)"
)


def test_second_call_builds_nothing(docker_client: docker.DockerClient) -> None:
    # Other work may change the copied sources between two calls; then the tag changes too and
    # the pair is retried.
    for _ in range(3):
        first = ensure_image("team-base", client=docker_client)
        second = ensure_image("team-base", client=docker_client)
        if first.reference == second.reference:
            break
    assert second.reference == first.reference
    assert second.rebuilt is False
    assert second.build_log is None
    assert second.image_id == first.image_id
    assert second.seconds < 10.0


def test_image_carries_its_content_hash_and_runs(docker_client: docker.DockerClient) -> None:
    reference = project_image("team-base")
    repository, _, content = reference.partition(":")
    assert repository == "hlvs-runner/team-base"
    labels = docker_client.images.get(reference).labels
    assert labels[LABEL_CONTENT] == content
    assert labels[LABEL_IMAGE] == "team-base"
    output = docker_client.containers.run(
        reference,
        ["python", "-c", CHECK],
        network_mode="none",
        remove=True,
        labels={"org.hlvs-runner.test": "1"},
    )
    assert output.decode().strip() == "(3, 11) True True"


def test_build_steps_show_as_progress(
    docker_client: docker.DockerClient, make_image: MakeImage, tmp_path: Path
) -> None:
    """A real build's ``Step n/m`` lines drive a progress task (plain lines off a terminal)."""
    base = make_image("hlvs-runner-test/progress-base:v1", 1000)
    (tmp_path / "extra.txt").write_text("x\n")
    (tmp_path / "Dockerfile").write_text(
        f'FROM {base}\nCOPY extra.txt /extra.txt\nLABEL {TEST_LABEL}="1"\n'
    )
    out = io.StringIO()
    task = PlainProgress(out=out, interval_s=0.0).add("build progress-test", unit="steps")
    reference = "hlvs-runner-test/progress-built:v1"
    try:
        engine_images.build(
            docker_client, context_dir=tmp_path, tag=reference, build_args={},
            labels={TEST_LABEL: "1"}, log_path=tmp_path / "build.log", network_mode="none",
            on_step=StepTracker(task),
        )
        task.finish()
    finally:
        try:
            docker_client.images.remove(reference, force=True)
        except docker.errors.APIError:
            pass
    lines = out.getvalue().splitlines()
    assert lines[0] == "build progress-test: started"
    # FROM, COPY, LABEL and the build's labels: four steps, each announced as it starts.
    assert "build progress-test: 2 steps of 4 steps (50 %)" in lines
    assert lines[-1].startswith("build progress-test: done, 4 steps, ")
