"""Public faces: a package imports another package only through that package's face.

A package's face is its ``__init__`` (which declares ``__all__``) plus the submodules listed in
ARCHITECTURE.md's "Public faces" table, each with the reason it is public on its own. The scan
reads every production module with ``ast`` (imports inside functions and ``TYPE_CHECKING``
blocks included) and fails on an import from another top-level package that goes past the face,
naming the file, the line and the module or name. The tools (``benchmarks``, ``testkit``)
measure and exercise internals as the tests do: their own imports are not checked, but what
``hlvs`` imports from them is.
"""

from __future__ import annotations

import ast
import re
from dataclasses import dataclass
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
PRODUCT = ("hlvs", "viewer", "service", "envs", "tournament", "cluster", "orchestrator",
           "simulator", "referee", "robot", "contracts")  # fmt: skip
TOOLS = ("benchmarks", "testkit")
PACKAGES = (*PRODUCT, *TOOLS)
TABLE_ROW = re.compile(r"^\| `(?P<module>[a-z_][a-z0-9_.]*)` +\|")


@dataclass(frozen=True)
class Import:
    where: str  # file:line
    module: str  # the module named after ``from`` / ``import``
    names: tuple[str, ...]  # the names after ``import`` in a from-import; () for ``import x``


def listed_faces() -> set[str]:
    """The public submodules of ARCHITECTURE.md's table (section "Public faces")."""
    text = (ROOT / "ARCHITECTURE.md").read_text(encoding="utf-8")
    section = text.split("## Public faces", 1)[1].split("\n## ", 1)[0]
    return {m["module"] for line in section.splitlines() if (m := TABLE_ROW.match(line))}


def module_path(module: str) -> Path | None:
    base = ROOT.joinpath(*module.split("."))
    if (base / "__init__.py").is_file():
        return base / "__init__.py"
    if base.with_suffix(".py").is_file():
        return base.with_suffix(".py")
    return None


def declared_all(path: Path) -> list[str] | None:
    """The literal ``__all__`` of a module, None where it declares none."""
    tree = ast.parse(path.read_text(encoding="utf-8"), filename=str(path))
    for node in tree.body:
        if isinstance(node, ast.Assign | ast.AnnAssign):
            targets = node.targets if isinstance(node, ast.Assign) else [node.target]
            if any(isinstance(t, ast.Name) and t.id == "__all__" for t in targets):
                assert node.value is not None
                return list(ast.literal_eval(node.value))
    return None


def cross_package_imports(packages: tuple[str, ...]) -> list[Import]:
    found = []
    for package in packages:
        for path in sorted((ROOT / package).rglob("*.py")):
            where = path.relative_to(ROOT).as_posix()
            tree = ast.parse(path.read_text(encoding="utf-8"), filename=str(path))
            for node in ast.walk(tree):
                if isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
                    entries = [(node.module, tuple(a.name for a in node.names))]
                elif isinstance(node, ast.Import):
                    entries = [(alias.name, ()) for alias in node.names]
                else:
                    continue
                for module, names in entries:
                    top = module.split(".")[0]
                    if top in PACKAGES and top != package:
                        found.append(Import(f"{where}:{node.lineno}", module, names))
    return found


def face_violations(imports: list[Import], faces: set[str]) -> list[str]:
    """Imports that go past a face: a module that is not a face, a submodule reached through
    ``from package import sub`` that is not one, or a name a face does not publish."""
    exported: dict[str, list[str] | None] = {}
    bad = []
    for imp in imports:
        if imp.module not in faces:
            bad.append(f"{imp.where}: {imp.module} is not a public face")
            continue
        path = module_path(imp.module)
        assert path is not None, imp
        names = exported.setdefault(imp.module, declared_all(path))
        for name in imp.names:
            if names is not None and name in names:
                continue  # a published name (a function may share its module's name)
            submodule = f"{imp.module}.{name}"
            if module_path(submodule) is not None:
                if submodule not in faces:
                    bad.append(f"{imp.where}: {submodule} is not a public face")
            elif name.startswith("_") or (names is not None and name not in names):
                bad.append(f"{imp.where}: {imp.module} does not publish {name}")
    return bad


def faces() -> set[str]:
    return set(PACKAGES) | listed_faces()


def test_every_package_declares_its_public_names() -> None:
    missing = [p for p in PACKAGES if declared_all(ROOT / p / "__init__.py") is None]
    assert missing == []


def test_every_listed_face_is_a_module_of_a_package() -> None:
    listed = listed_faces()
    assert "contracts.ids" in listed  # the table was found and read
    assert sorted(m for m in listed if module_path(m) is None) == []
    assert sorted(m for m in listed if m.split(".")[0] not in PACKAGES) == []
    # a listed package face publishes its names like a top-level one
    packages = [m for m in listed if (path := module_path(m)) and path.name == "__init__.py"]
    assert sorted(m for m in packages if declared_all(module_path(m)) is None) == []  # type: ignore[arg-type]


def test_imports_between_packages_go_through_public_faces() -> None:
    imports = cross_package_imports(PRODUCT)
    assert len(imports) > 300  # the scan saw the real tree
    assert face_violations(imports, faces()) == []


def test_every_listed_face_is_used_by_another_package() -> None:
    used = {imp.module for imp in cross_package_imports(PACKAGES)}
    used |= {f"{imp.module}.{n}" for imp in cross_package_imports(PACKAGES) for n in imp.names}
    assert sorted(listed_faces() - used) == []


def test_the_check_catches_imports_past_a_face() -> None:
    face = {"orchestrator", "contracts.files"}
    imports = [
        Import("a.py:1", "orchestrator.errors", ("ConfigError",)),
        Import("a.py:2", "orchestrator", ("ConfigError",)),
        Import("a.py:3", "orchestrator", ("paths",)),
        Import("a.py:4", "orchestrator", ("NotAName",)),
        Import("a.py:5", "contracts", ("files",)),
        Import("a.py:6", "contracts.files", ("_private",)),
    ]
    assert face_violations(imports, face | {"contracts"}) == [
        "a.py:1: orchestrator.errors is not a public face",
        "a.py:3: orchestrator.paths is not a public face",
        "a.py:4: orchestrator does not publish NotAName",
        "a.py:6: contracts.files does not publish _private",
    ]
