"""Team images through a real registry: push, pull with the team's login, pinned digests, and
the precise error for each way a pull fails."""

from __future__ import annotations

from pathlib import Path

import docker
import pytest

from orchestrator.config import Limits, PlayerConfig, RegistryAuth, StartingPose, TeamConfig
from orchestrator.errors import ImagePullError, ImageTooLarge
from orchestrator.pull import resolve_team_images
from tests.conftest import TEST_LABEL
from tests.integration.images.conftest import MakeImage, Registry, free_port, push

pytestmark = pytest.mark.docker

POSE = StartingPose(translation=(-1.0, -3.2, 0.4), rotation=(0.0, 0.0, 1.0, 1.57))


def team(
    image: str | None, tag: str | None, auth: RegistryAuth | None, players: int = 2
) -> TeamConfig:
    return TeamConfig(
        source=Path("team_config.json"),
        name="Alpha",
        image=image,
        registry_auth=auth,
        players=tuple(
            PlayerConfig(
                number=n,
                half_time_pose=POSE,
                reentry_pose=POSE,
                shootout_pose=POSE,
                goalkeeper_pose=POSE,
                model="kid-default",
                image_repository=image,
                docker_tag=tag,
            )
            for n in range(1, players + 1)
        ),
    )


def alpha_login(registry: Registry, password: str | None = None) -> RegistryAuth:
    return RegistryAuth(username="alpha", password=password or registry.users["alpha"])


@pytest.mark.slow
def test_team_image_on_team_base_is_pushed_pulled_pinned_and_runs(
    registry: Registry, docker_client: docker.DockerClient, tmp_path: Path
) -> None:
    from orchestrator.project_images import project_image

    # The team's side, as images/README.md tells it: build FROM team-base, push.
    (tmp_path / "player.py").write_text(
        "import os, robot.client\n"
        "print(os.environ['ROBOCUP_TEAM_COLOR'], os.environ['ROBOCUP_ROBOT_ID'], 'client ok')\n"
    )
    (tmp_path / "Dockerfile").write_text(
        f"FROM {project_image('team-base')}\nCOPY player.py /robot/player.py\n"
        'CMD ["python", "/robot/player.py"]\n'
    )
    repository = f"{registry.host}/alpha/robot"
    docker_client.images.build(
        path=str(tmp_path), tag=f"{repository}:v1", network_mode="none", labels={TEST_LABEL: "1"},
        rm=True, forcerm=True,
    )
    pushed = push(docker_client, f"{repository}:v1", "alpha", registry.users["alpha"])
    docker_client.images.remove(f"{repository}:v1")  # the match host starts from nothing

    resolved = resolve_team_images(
        docker_client, team(repository, "v1", alpha_login(registry)), limits=Limits()
    )

    assert sorted(resolved) == [1, 2]
    for number, image in resolved.items():
        assert image.error is None, image.error
        assert image.number == number
        assert image.reference == f"{repository}:v1"
        assert image.digest == f"{repository}@{pushed}"
        assert image.size_bytes > 100_000_000
    output = docker_client.containers.run(
        resolved[1].digest,
        environment={"ROBOCUP_TEAM_COLOR": "red", "ROBOCUP_ROBOT_ID": "1"},
        network_mode="none",
        remove=True,
        labels={TEST_LABEL: "1"},
    )
    assert output.decode().strip() == "red 1 client ok"


def test_pull_of_a_small_image_pins_digest(
    registry: Registry, docker_client: docker.DockerClient, make_image: MakeImage
) -> None:
    repository = f"{registry.host}/alpha/small"
    make_image(f"{repository}:v1", 10_000)
    pushed = push(docker_client, f"{repository}:v1", "alpha", registry.users["alpha"])
    docker_client.images.remove(f"{repository}:v1")

    resolved = resolve_team_images(
        docker_client, team(repository, "v1", alpha_login(registry), players=1), limits=Limits()
    )

    assert resolved[1].error is None
    assert resolved[1].digest == f"{repository}@{pushed}"


def test_wrong_password_names_registry_and_user(
    registry: Registry, docker_client: docker.DockerClient, make_image: MakeImage
) -> None:
    repository = f"{registry.host}/alpha/robot"
    make_image(f"{repository}:v1", 1000)
    push(docker_client, f"{repository}:v1", "alpha", registry.users["alpha"])
    docker_client.images.remove(f"{repository}:v1")

    resolved = resolve_team_images(
        docker_client, team(repository, "v1", alpha_login(registry, "wrong")), limits=Limits()
    )

    error = resolved[1].error
    assert isinstance(error, ImagePullError)
    assert error.reason.startswith(f"authentication failed for {registry.host} (user alpha)")
    assert resolved[2].error is error  # one pull per distinct image
    assert resolved[1].digest == ""


def test_unknown_tag_names_tag_and_repository(
    registry: Registry, docker_client: docker.DockerClient, make_image: MakeImage
) -> None:
    repository = f"{registry.host}/alpha/robot"
    make_image(f"{repository}:v1", 1000)
    push(docker_client, f"{repository}:v1", "alpha", registry.users["alpha"])

    resolved = resolve_team_images(
        docker_client, team(repository, "nope", alpha_login(registry)), limits=Limits()
    )

    error = resolved[1].error
    assert isinstance(error, ImagePullError)
    assert error.reason == f"tag nope not found in {repository}"


def test_unreachable_registry(docker_client: docker.DockerClient) -> None:
    host = f"127.0.0.1:{free_port()}"  # nothing listens there
    resolved = resolve_team_images(
        docker_client,
        team(f"{host}/alpha/robot", "v1", RegistryAuth(username="alpha", password="x")),
        limits=Limits(),
    )

    error = resolved[1].error
    assert isinstance(error, ImagePullError)
    assert error.reason.startswith(f"registry {host} unreachable: ")


def test_missing_password_env_is_an_auth_error(docker_client: docker.DockerClient) -> None:
    auth = RegistryAuth(username="alpha", password_env="HLVS_TEST_UNSET_PASSWORD")
    resolved = resolve_team_images(
        docker_client, team("127.0.0.1:9/alpha/robot", "v1", auth), limits=Limits(), environ={}
    )

    error = resolved[1].error
    assert isinstance(error, ImagePullError)
    assert "HLVS_TEST_UNSET_PASSWORD is not set" in error.reason


def test_image_over_limit_is_refused_and_removed(
    registry: Registry, docker_client: docker.DockerClient, make_image: MakeImage
) -> None:
    repository = f"{registry.host}/alpha/big"
    make_image(f"{repository}:v1", 20_000)
    push(docker_client, f"{repository}:v1", "alpha", registry.users["alpha"])
    docker_client.images.remove(f"{repository}:v1")

    resolved = resolve_team_images(
        docker_client,
        team(repository, "v1", alpha_login(registry)),
        limits=Limits(image_gb=10_000 / 1e9),
    )

    error = resolved[1].error
    assert isinstance(error, ImageTooLarge)
    assert error.size_bytes > error.limit_bytes == 10_000
    with pytest.raises(docker.errors.ImageNotFound):
        docker_client.images.get(f"{repository}:v1")


def test_local_only_image_is_used_as_is(
    docker_client: docker.DockerClient, make_image: MakeImage
) -> None:
    reference = make_image("hlvs-runner-test/local-robot:v1", 1000)
    image_id = docker_client.images.get(reference).id

    resolved = resolve_team_images(
        docker_client, team("hlvs-runner-test/local-robot", "v1", None), limits=Limits()
    )

    assert resolved[1].error is None
    assert resolved[1].image_id == image_id
    assert resolved[1].digest == image_id


def test_player_without_image(docker_client: docker.DockerClient) -> None:
    resolved = resolve_team_images(docker_client, team(None, None, None), limits=Limits())
    assert resolved[1].error is not None
    assert "no image named for player 1" in str(resolved[1].error)


def test_hlvs_images_pull_reports_each_player(
    registry: Registry,
    docker_client: docker.DockerClient,
    make_image: MakeImage,
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    import json

    from hlvs.cli import main

    repository = f"{registry.host}/alpha/robot"
    make_image(f"{repository}:v1", 1000)
    pushed = push(docker_client, f"{repository}:v1", "alpha", registry.users["alpha"])
    example = Path(__file__).parents[3] / "configs" / "examples" / "scrimmage_1v1"
    document = json.loads((example / "team_red.json").read_text())
    document["image"] = repository
    document["players"]["1"]["dockerTag"] = "v1"
    document["registry_auth"] = {"username": "alpha", "password_env": "HLVS_TEST_ALPHA_PASSWORD"}
    config = tmp_path / "team_config.json"
    config.write_text(json.dumps(document))

    monkeypatch.setenv("HLVS_TEST_ALPHA_PASSWORD", registry.users["alpha"])
    assert main(["images", "pull", str(config), "--json"]) == 0
    report = json.loads(capsys.readouterr().out)
    assert report["players"]["1"]["digest"] == f"{repository}@{pushed}"
    assert report["players"]["1"]["error"] is None

    monkeypatch.setenv("HLVS_TEST_ALPHA_PASSWORD", "wrong")
    assert main(["images", "pull", str(config), "--json"]) == 1
    error = json.loads(capsys.readouterr().out)["players"]["1"]["error"]
    assert error.startswith(f"authentication failed for {registry.host} (user alpha)")


def test_pull_game_images_pins_both_teams(docker_client: docker.DockerClient) -> None:
    from orchestrator.project_images import project_image
    from orchestrator.pull import pull_game_images

    project_image("stub")  # also tags hlvs-runner/stub:latest, which the example names
    game = Path(__file__).parents[3] / "configs" / "examples" / "scrimmage_1v1" / "game.json"

    pulled = pull_game_images(game, engine=docker_client)

    assert pulled.ok
    assert str(pulled) == "red: 1/1 images pinned; blue: 1/1 images pinned"
    image_id = pulled.teams["red"][1].image_id
    assert pulled.teams["blue"][1].image_id == image_id
    assert docker_client.images.get(image_id).labels["org.hlvs-runner.image"] == "stub"
