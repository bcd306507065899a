"""Shared test settings. Integration tests mark what they need (docker, root), clean up by label.

``make test`` runs the suite on two pytest-xdist workers (``--dist loadgroup``). Each folder of
``tests/integration`` (and each file directly in it) is one group, run by one worker from start
to end: a folder's tests share session fixtures that are one of a kind on the machine (the Slurm
cluster, a registry) and were written to run one after another. Two groups, or a group and the
in-process tests, may run at once: they share nothing but the Docker engine, where every match
has its own id, networks and containers. Most integration tests wait on matches played in real
time, so the second worker uses CPU the first leaves idle. Every other test module is a group
of its own (its module fixtures are built once).
"""

from __future__ import annotations

import os
from pathlib import Path

import pytest

# Offscreen rendering without a display (MuJoCo reads this at import time).
os.environ.setdefault("MUJOCO_GL", "osmesa")
os.environ.setdefault("PYOPENGL_PLATFORM", "osmesa")

TEST_LABEL = "org.hlvs-runner.test"

_TESTS = Path(__file__).resolve().parent


def worker_group(path: Path) -> str:
    """The group a test file belongs to: its integration folder, else the file itself."""
    relative = path.resolve().relative_to(_TESTS)
    if relative.parts[0] == "integration" and len(relative.parts) > 1:
        return "/".join(relative.parts[:2])
    return relative.as_posix()


def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    for item in items:
        item.add_marker(pytest.mark.xdist_group(worker_group(item.path)))
