"""Every example shipped under configs/examples passes ``hlvs check`` (exit 0, warnings allowed):
each game, team, credentials and schedule file, and each robot model package folder. The other
files there (key files, known_hosts, meshes, READMEs) are what those examples point to."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest

from tests.unit.config.conftest import EXAMPLES

CONFIG_SUFFIXES = {".json", ".yaml", ".yml"}


def _model_packages() -> list[Path]:
    return sorted(p.parent for p in EXAMPLES.rglob("robot_model.json"))


def _config_files() -> list[Path]:
    packages = _model_packages()
    return sorted(
        p for p in EXAMPLES.rglob("*")
        if p.is_file() and p.suffix in CONFIG_SUFFIXES
        and not any(p.is_relative_to(package) for package in packages)
    )  # fmt: skip


def _name(path: Path) -> str:
    return str(path.relative_to(EXAMPLES))


def test_the_examples_are_found() -> None:
    names = {_name(p) for p in _config_files()}
    assert {"credentials/sftp_key.json", "schedule/tournament.yaml",
            "kid_4v4_official/game.json"} <= names  # fmt: skip
    assert [_name(p) for p in _model_packages()] == ["robots/wolfgang"]


@pytest.mark.parametrize("path", _config_files() + _model_packages(), ids=_name)
def test_every_example_passes_hlvs_check(path: Path, hlvs_check: Any) -> None:
    run = hlvs_check(path)
    assert run.code == 0, run.out + run.err
    assert f"{path}: ok" in run.out
