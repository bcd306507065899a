"""Who may import whom: tests never import the benchmarks; no production package imports the
benchmarks or the test kit; the contracts and the robot package stay light (their own tests:
tests/unit/contracts, tests/unit/stub/test_robot_imports.py)."""

from __future__ import annotations

import ast
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
PRODUCTION = ("orchestrator", "simulator", "referee", "robot", "contracts", "service", "envs",
              "viewer")  # fmt: skip


def imported_tops(path: Path) -> set[str]:
    tree = ast.parse(path.read_text(encoding="utf-8"), filename=str(path))
    tops: set[str] = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            tops.update(alias.name.split(".")[0] for alias in node.names)
        elif isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            tops.add(node.module.split(".")[0])
    return tops


BENCH_DISPATCH = "orchestrator/commands/simulator.py"  # `hlvs bench KIND` runs the benchmarks


def offenders(folders: tuple[str, ...], forbidden: set[str]) -> list[str]:
    found = []
    for folder in folders:
        for path in sorted((ROOT / folder).rglob("*.py")):
            if path.relative_to(ROOT).as_posix() == BENCH_DISPATCH:
                continue
            bad = imported_tops(path) & forbidden
            if bad:
                found.append(f"{path.relative_to(ROOT)}: {sorted(bad)}")
    return found


def test_tests_import_nothing_from_the_benchmarks() -> None:
    assert (ROOT / "benchmarks" / "sim.py").is_file()  # the scan looks at the real tree
    assert offenders(("tests",), {"benchmarks"}) == []


def test_production_packages_import_neither_benchmarks_nor_the_test_kit() -> None:
    assert offenders(PRODUCTION, {"benchmarks", "testkit"}) == []
