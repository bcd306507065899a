"""Attacks from real robot containers in real matches: a hostile robot image built on the team
base image, short lockstep matches played by ``hlvs match`` from files written as ``hlvs
scrimmage`` writes them (the hostile robot is red 1, blue plays the stub)."""

from __future__ import annotations

import argparse
import hashlib
import io
import json
import os
import subprocess
import sys
import tarfile
import uuid
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import docker
import pytest

from orchestrator.errors import OrchestratorError
from orchestrator.match import scrimmage

ASSETS = Path(__file__).parent / "assets"
REPO = Path(__file__).resolve().parents[3]


@pytest.fixture(scope="session")
def project_images() -> dict[str, str]:
    try:
        from orchestrator.project_images import project_image

        return {name: project_image(name) for name in ("simulator", "stub", "team-base")}
    except (ImportError, OrchestratorError) as exc:
        pytest.skip(f"project images unavailable: {exc}")


@pytest.fixture(scope="session")
def attack_image(docker_client: docker.DockerClient, project_images: dict[str, str]) -> str:
    script = (ASSETS / "attacker.py").read_bytes()
    dockerfile = (f"FROM {project_images['team-base']}\nCOPY attacker.py /opt/a/attacker.py\n"
                  "CMD [\"python3\", \"/opt/a/attacker.py\"]\n").encode()
    tag = "hlvs-runner-test/attacker:" + hashlib.sha256(dockerfile + script).hexdigest()[:12]
    try:
        docker_client.images.get(tag)
        return tag
    except docker.errors.ImageNotFound:
        pass
    buffer = io.BytesIO()
    with tarfile.open(fileobj=buffer, mode="w") as tar:
        for name, data in (("attacker.py", script), ("Dockerfile", dockerfile)):
            info = tarfile.TarInfo(name)
            info.size = len(data)
            tar.addfile(info, io.BytesIO(data))
    buffer.seek(0)
    docker_client.images.build(fileobj=buffer, custom_context=True, tag=tag,
                               network_mode="none",
                               labels={"org.hlvs-runner.test-image": "attacker"},
                               rm=True, forcerm=True)
    return tag


@dataclass(frozen=True, slots=True)
class Prepared:
    match_id: str
    game: Path
    out: Path

    def command(self, *extra: str) -> list[str]:
        return [sys.executable, "-m", "hlvs", "match", str(self.game), "--out",
                str(self.out), *extra]

    def run(self, timeout_s: float = 240.0) -> subprocess.CompletedProcess[str]:
        return subprocess.run(self.command(), capture_output=True, text=True, timeout=timeout_s,
                              cwd=REPO, env=_env(), check=False)

    def start(self) -> subprocess.Popen[str]:
        return subprocess.Popen(self.command(), stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                                text=True, cwd=REPO, env=_env())

    def results(self) -> dict[str, Any]:
        data: dict[str, Any] = json.loads((self.out / "results.json").read_text())
        return data

    def report(self) -> dict[str, Any]:
        data: dict[str, Any] = json.loads((self.out / "report.json").read_text())
        return data


def _env() -> dict[str, str]:
    return {**os.environ, "PYTHONPATH": str(REPO)}


Prepare = Callable[..., Prepared]


@pytest.fixture(scope="module")
def prepare(tmp_path_factory: pytest.TempPathFactory, attack_image: str,
            project_images: dict[str, str]) -> Iterator[Prepare]:
    """``prepare("spoof", "special-files", half_s=4, game={...}) -> Prepared``: red 1 runs the
    attacks, blue 1 is a stub goalie."""
    made: list[str] = []
    tmp_path = tmp_path_factory.mktemp("attack")

    def factory(*attacks: str, half_s: float = 4.0, players: int = 1,
                game: dict[str, Any] | None = None, red: dict[str, Any] | None = None
                ) -> Prepared:
        match_id = f"attack-{uuid.uuid4().hex[:8]}"
        made.append(match_id)
        out = tmp_path / match_id
        args = argparse.Namespace(
            red_image=attack_image, blue_image=project_images["stub"], players=players,
            half_duration=half_s, ready_duration=1.0, minimum_play=0.0, wait_before_ready=1.0,
            grace=2.0,
            robot_command=None,
            match_id=match_id, seed=42,
        )
        config = tmp_path / f"{match_id}-config"
        game_path = scrimmage.write_files(scrimmage.ScrimmageRequest.from_options(args), config)
        team_path = config / "team_red.json"
        team = json.loads(team_path.read_text())
        for entry in team["players"].values():
            entry["dockerCmd"] = "python3 /opt/a/attacker.py " + " ".join(attacks)
        team.update(red or {})
        team_path.write_text(json.dumps(team, indent=2))
        if game:
            data = json.loads(game_path.read_text())
            for key, value in game.items():
                if isinstance(value, dict) and isinstance(data.get(key), dict):
                    data[key].update(value)
                else:
                    data[key] = value
            game_path.write_text(json.dumps(data, indent=2))
        return Prepared(match_id=match_id, game=game_path, out=out)

    yield factory
    for match_id in made:
        subprocess.run([sys.executable, "-m", "hlvs", "cleanup", "--match", match_id],
                       capture_output=True, text=True, timeout=120, cwd=REPO, env=_env(),
                       check=False)


def left_behind(client: docker.DockerClient, match_id: str) -> list[str]:
    """Containers and networks of ``match_id`` still on the engine, and its log mounts."""
    from orchestrator.engine import LABEL_MATCH

    found = [c.name for c in client.containers.list(
        all=True, filters={"label": f"{LABEL_MATCH}={match_id}"})]
    found += [n.name for n in client.networks.list(
        filters={"label": f"{LABEL_MATCH}={match_id}"})]
    mounts = Path("/proc/mounts").read_text().split("\n")
    found += [line for line in mounts if f"/logfs/{match_id}/" in line]
    return found


# The module fixtures that play a hostile match play it twice: with the robots under the
# engine's default runtime and under gVisor's runsc (registered by ``make test``).
RUNTIMES = {"params": [None, "runsc"], "ids": ["default-runtime", "gvisor"]}


def under_runtime(runtime: str | None, docker_client: docker.DockerClient,
                  limits: dict[str, Any]) -> dict[str, Any]:
    """``limits`` with ``robot_runtime`` set to ``runtime``; skips when the engine lacks it."""
    if runtime is None:
        return limits
    if runtime not in docker_client.info().get("Runtimes", {}):
        pytest.skip(f"the engine has no {runtime} runtime (see configs/README.md)")
    return {**limits, "robot_runtime": runtime}
