"""Team code imports only the robot package: no simulator server, referee or MuJoCo."""

from __future__ import annotations

import subprocess
import sys

import pytest

FORBIDDEN = ("simulator", "referee", "orchestrator", "benchmarks", "mujoco", "zenoh", "docker")


def imported_modules(statement: str) -> set[str]:
    """Every module ``python -X importtime -c statement`` loads, in a fresh interpreter."""
    result = subprocess.run(
        [sys.executable, "-X", "importtime", "-c", statement],
        capture_output=True,
        text=True,
        check=True,
        timeout=120,
    )
    modules = set()
    for line in result.stderr.splitlines():
        if line.startswith("import time:") and "|" in line:
            name = line.rsplit("|", 1)[1].strip()
            if name != "imported package":
                modules.add(name)
    return modules


@pytest.mark.parametrize(
    "statement",
    [
        "import robot.client",
        "import robot.stub, robot.stub.runner",
        "import robot.motion, robot.geometry",
    ],
)
def test_robot_modules_import_no_server_side_module(statement: str) -> None:
    modules = imported_modules(statement)
    assert statement.split()[1].rstrip(",") in modules
    heavy = sorted(m for m in modules if m.split(".")[0] in FORBIDDEN)
    assert heavy == []
    assert "contracts.robot_api.messages_pb2" in modules or statement.endswith("geometry")
