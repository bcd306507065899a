"""Shared test settings. Integration tests mark what they need (docker, root), clean up by label.

``make test`` runs the suite on two pytest-xdist workers (``--dist loadgroup``). Each folder of
``tests/integration`` (and each file directly in it) is one group, run by one worker from start
to end: its tests were written to run one after another. A test that uses a fixture of which
the machine has one (the Slurm cluster) joins the group of that fixture's folder
(:data:`ONE_OF_A_KIND`). Two groups, or a group and the in-process tests, may run at once: they
share only the Docker engine, where every match has its own id, networks and containers, and
PostgreSQL, where every test has its own database. Most integration tests wait on matches
played in real time, so the second worker uses CPU the first leaves idle. Every other test
module is a group of its own (its module fixtures are built once).
"""

from __future__ import annotations

import os
from collections.abc import Iterable
from pathlib import Path

import pytest

# Offscreen rendering without a display (MuJoCo reads this at import time).
os.environ.setdefault("MUJOCO_GL", "osmesa")
os.environ.setdefault("PYOPENGL_PLATFORM", "osmesa")

TEST_LABEL = "org.hlvs-runner.test"

_TESTS = Path(__file__).resolve().parent


# Fixtures of which the machine has one, and the group of every test that uses them: the Slurm
# cluster (its daemons, nodes and accounting) is the pool folder's, wherever a test uses it.
ONE_OF_A_KIND = {"cluster": "integration/pool"}


def worker_group(path: Path, fixtures: Iterable[str] = ()) -> str:
    """The group of a test: that of a one-of-a-kind fixture it uses, else its integration
    folder, else its file."""
    for name in fixtures:
        if name in ONE_OF_A_KIND:
            return ONE_OF_A_KIND[name]
    relative = path.resolve().relative_to(_TESTS)
    if relative.parts[0] == "integration" and len(relative.parts) > 1:
        return "/".join(relative.parts[:2])
    return relative.as_posix()


def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    for item in items:
        fixtures = getattr(item, "fixturenames", ())
        item.add_marker(pytest.mark.xdist_group(worker_group(item.path, fixtures)))
