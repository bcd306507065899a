"""Who may import whom: tests never import the benchmarks; no production package imports the
benchmarks or the test kit; the contracts and the robot package stay light (their own tests:
tests/unit/contracts, tests/unit/stub/test_robot_imports.py)."""

from __future__ import annotations

import ast
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
PRODUCTION = ("orchestrator", "simulator", "referee", "robot", "contracts", "service", "envs",
              "cluster", "tournament",
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


# `hlvs bench KIND` runs the benchmarks: these command modules import them inside the command.
BENCH_DISPATCH = {"hlvs/commands/simulator.py", "hlvs/commands/service.py"}


def offenders(folders: tuple[str, ...], forbidden: set[str]) -> list[str]:
    found = []
    for folder in folders:
        for path in sorted((ROOT / folder).rglob("*.py")):
            if path.relative_to(ROOT).as_posix() in BENCH_DISPATCH:
                continue
            bad = imported_tops(path) & forbidden
            if bad:
                found.append(f"{path.relative_to(ROOT)}: {sorted(bad)}")
    return found


def test_tests_import_nothing_from_the_benchmarks() -> None:
    assert (ROOT / "benchmarks" / "sim.py").is_file()  # the scan looks at the real tree
    assert offenders(("tests",), {"benchmarks"}) == []


def test_no_benchmark_lives_in_a_production_package() -> None:
    found = [
        str(path.relative_to(ROOT))
        for package in PRODUCTION
        for path in sorted((ROOT / package).rglob("*.py"))
        if "bench" in path.stem
    ]
    assert (ROOT / "benchmarks" / "api.py").is_file()
    assert found == []


def test_production_packages_import_neither_benchmarks_nor_the_test_kit() -> None:
    assert offenders(PRODUCTION, {"benchmarks", "testkit"}) == []


def module_level_imports(path: Path, package_root: Path) -> set[str]:
    """Modules of our packages imported at module level (TYPE_CHECKING blocks included)."""
    tree = ast.parse(path.read_text(encoding="utf-8"), filename=str(path))
    found: set[str] = set()
    nodes: list[ast.stmt] = list(tree.body)
    while nodes:
        node = nodes.pop()
        if isinstance(node, ast.If | ast.Try):
            nodes.extend(node.body)
            nodes.extend(getattr(node, "orelse", []))
        elif isinstance(node, ast.Import):
            found.update(alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            found.add(node.module)
            found.update(f"{node.module}.{alias.name}" for alias in node.names)
    return found


def import_cycles(package: str) -> list[list[str]]:
    modules: dict[str, Path] = {}
    for path in (ROOT / package).rglob("*.py"):
        parts = path.relative_to(ROOT).with_suffix("").parts
        name = ".".join(parts[:-1] if parts[-1] == "__init__" else parts)
        modules[name] = path
    graph = {
        name: {m for m in module_level_imports(path, ROOT) if m in modules and m != name}
        for name, path in modules.items()
    }
    packages = {name for name, path in modules.items() if path.name == "__init__.py"}
    cycles: list[list[str]] = []

    def visit(node: str, trail: list[str]) -> None:
        for nxt in sorted(graph[node]):
            if nxt in packages:
                continue  # a package's __init__ re-exporting its modules is not a circle
            if nxt in trail:
                cycles.append(trail[trail.index(nxt):] + [nxt])
            elif len(trail) < 12:
                visit(nxt, [*trail, nxt])

    for start in sorted(graph):
        if start not in packages:
            visit(start, [start])
    return cycles


def test_the_match_phases_form_no_import_circle() -> None:
    assert (ROOT / "orchestrator" / "match" / "deps.py").is_file()
    cycles = [c for c in import_cycles("orchestrator") if c[0].startswith("orchestrator.match")]
    assert cycles == []


def test_no_package_has_an_import_circle() -> None:
    found = {package: import_cycles(package)[:1] for package in (*PRODUCTION, "testkit")}
    assert {package: cycle for package, cycle in found.items() if cycle} == {}


def test_the_match_domain_does_not_import_the_command_line() -> None:
    found = []
    for path in sorted((ROOT / "orchestrator" / "match").rglob("*.py")):
        modules = module_level_imports(path, ROOT)
        if any(m.startswith("hlvs.commands") or m == "argparse" for m in modules):
            found.append(str(path.relative_to(ROOT)))
    assert (ROOT / "orchestrator" / "match" / "scrimmage.py").is_file()
    assert found == []
