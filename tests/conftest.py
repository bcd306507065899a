"""Shared test settings. Integration tests mark what they need (docker, root), clean up by label.

``make test`` runs the suite on two pytest-xdist workers (``--dist loadgroup``), by groups
(:func:`worker_group`). Each folder of ``tests/integration`` (and each file directly in it) is
one group, run by one worker from start to end: its tests were written to run one after
another. A test that uses a fixture of which the machine has one (the Slurm cluster) joins the
group of that fixture's folder (:data:`ONE_OF_A_KIND`). Two groups, or a group and the
in-process tests, may run at once: they share only the Docker engine, where every match has its
own id, networks and containers, and PostgreSQL, where every test has its own database. Most
integration tests wait on matches played in real time, so the second worker uses CPU the first
leaves idle. Every other test module is a group of its own (its module fixtures are built once).
"""

from __future__ import annotations

import os
from pathlib import PurePosixPath
from typing import Any

import pytest

# Offscreen rendering without a display (MuJoCo reads this at import time).
os.environ.setdefault("MUJOCO_GL", "osmesa")
os.environ.setdefault("PYOPENGL_PLATFORM", "osmesa")

TEST_LABEL = "org.hlvs-runner.test"

# Test files outside a one-of-a-kind fixture's folder that use it, and that folder's group: the
# Slurm cluster (its daemons, nodes and accounting) of tests/integration/pool/conftest.py. The
# scheduler sees test ids only, so files are named here (tests/unit/test_worker_groups.py checks
# that every user of the fixture is).
ONE_OF_A_KIND = {
    "integration/viewer/test_viewer_pool_nodes.py": "integration/pool",
}


def worker_group(nodeid: str) -> str:
    """The group of a test id (``tests/...py::name``): that of a one-of-a-kind fixture its file
    uses, else its integration folder, else its file."""
    path = PurePosixPath(nodeid.split("::", 1)[0])
    parts = path.parts[1:] if path.parts and path.parts[0] == "tests" else path.parts
    relative = "/".join(parts)
    if relative in ONE_OF_A_KIND:
        return ONE_OF_A_KIND[relative]
    if len(parts) > 2 and parts[0] == "integration":
        return "/".join(parts[:2])
    return relative


def pytest_xdist_make_scheduler(config: pytest.Config, log: Any) -> Any:
    """``--dist loadgroup``: whole groups of :func:`worker_group` to a worker at a time, in the
    order collected (with ``--no-loadscope-reorder``)."""
    if config.getvalue("dist") != "loadgroup":
        return None
    from xdist.scheduler import LoadScopeScheduling

    class GroupScheduling(LoadScopeScheduling):
        def _split_scope(self, nodeid: str) -> str:
            return worker_group(nodeid)

    return GroupScheduling(config, log)
