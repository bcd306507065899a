"""Each package has one sorted public surface, and every name in it exists."""

from __future__ import annotations

import importlib

import pytest


@pytest.mark.parametrize("package", ["orchestrator", "simulator", "referee", "service", "envs"])
def test_all_is_sorted_and_resolves(package: str) -> None:
    module = importlib.import_module(package)
    names = list(module.__all__)
    assert names == sorted(names, key=str.casefold) or names == sorted(names)
    for name in names:
        assert hasattr(module, name), f"{package}.{name} is exported but missing"


def test_referee_imports_neither_mujoco_nor_docker() -> None:
    import subprocess
    import sys

    code = (
        "import sys, referee, referee.snapshot, contracts.field;"
        "bad=[m for m in ('mujoco','docker') if m in sys.modules];"
        "print(','.join(bad))"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == ""
