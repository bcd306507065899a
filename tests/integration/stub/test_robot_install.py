"""The robot package installs on its own: a fresh venv with only its dependencies (numpy,
protobuf, the contracts) runs the client and the stub without MuJoCo, simulator or referee."""

from __future__ import annotations

import shutil
import subprocess
import venv
from pathlib import Path

import pytest

from orchestrator import image_inputs
from orchestrator.project_images import BUILD_DIR, ROBOT_REQUIREMENTS
from tests.unit.stub.test_robot_imports import FORBIDDEN

REPO = Path(__file__).resolve().parents[3]

pytestmark = pytest.mark.slow


def test_robot_package_installs_alone_and_imports_no_server_module(tmp_path: Path) -> None:
    assert ROBOT_REQUIREMENTS == ("numpy", "protobuf")  # read from robot/ and contracts/
    wheels = image_inputs.ensure_wheels(
        image_inputs.pinned_requirements(ROBOT_REQUIREMENTS), cache_dir=BUILD_DIR / "wheels"
    )
    sources = tmp_path / "src"  # pip builds in the source folder: keep the tree clean
    for package in ("contracts", "robot"):
        shutil.copytree(
            REPO / package, sources / package, ignore=shutil.ignore_patterns("__pycache__")
        )
    env_dir = tmp_path / "venv"
    venv.create(env_dir, with_pip=True)
    python = str(env_dir / "bin" / "python")
    subprocess.run(
        [python, "-m", "pip", "install", "--quiet", "--find-links", str(wheels),
         "-r", str(wheels / "requirements.txt"),
         str(sources / "contracts"), str(sources / "robot")],
        check=True, capture_output=True, text=True, timeout=600, cwd=tmp_path,
    )  # fmt: skip
    listed = subprocess.run(
        [python, "-m", "pip", "list", "--format=freeze"],
        check=True, capture_output=True, text=True, cwd=tmp_path,
    ).stdout.lower()  # fmt: skip
    installed = {line.split("==")[0] for line in listed.splitlines()}
    assert {"hlvs-robot", "hlvs-contracts", "numpy", "protobuf"} <= installed
    assert "mujoco" not in installed and "hlvs-runner" not in installed

    result = subprocess.run(
        [python, "-X", "importtime", "-c",
         "import robot.client, robot.stub.runner, robot.motion; print(robot.client.__file__)"],
        check=True, capture_output=True, text=True, timeout=120, cwd=tmp_path,
    )  # fmt: skip
    assert str(env_dir) in result.stdout  # the installed copy, not the source tree
    modules = {
        line.rsplit("|", 1)[1].strip()
        for line in result.stderr.splitlines()
        if line.startswith("import time:") and "|" in line
    }
    assert "robot.client" in modules and "contracts.robot_api.messages_pb2" in modules
    assert sorted(m for m in modules if m.split(".")[0] in FORBIDDEN) == []
    # The stub's entry point runs from the installed copy (a bad behaviour name: usage error).
    stub = subprocess.run(
        [python, "-m", "robot.stub", "dribbler"], capture_output=True, text=True, cwd=tmp_path
    )
    assert stub.returncode == 2, stub.stderr
    assert "got 'dribbler', expected striker" in stub.stderr
