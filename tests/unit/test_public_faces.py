"""Public faces: a package imports another top-level package only through a package's face.

A face is a package's ``__init__``: the names in its ``__all__``. An import from another
top-level package names a package (a directory with ``__init__.py``: a top-level package or a
sub-package such as ``simulator.world``) and only names in its ``__all__``; never a plain module.
The scan reads every production module with ``ast`` (imports inside functions and
``TYPE_CHECKING`` blocks included) and names the file, the line and the import that goes past a
face. The faces' lazy maps (``contracts.lazy_exports``) are checked against their
``TYPE_CHECKING`` imports and ``__all__``, and, in a fresh interpreter, every published name of
every face is looked up. The tools (``benchmarks``, ``testkit``) measure and exercise internals
as the tests do: their own imports are not checked, but what ``hlvs`` imports from them is.
"""

from __future__ import annotations

import ast
import functools
import json
import re
import subprocess
import sys
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


def module_path(module: str) -> Path | None:
    base = ROOT.joinpath(*module.split("."))
    if (base / "__init__.py").is_file():
        return base / "__init__.py"
    if base.with_suffix(".py").is_file():
        return base.with_suffix(".py")
    return None


def is_package(module: str) -> bool:
    path = module_path(module)
    return path is not None and path.name == "__init__.py"


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


@functools.cache
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


def face_violations(imports: list[Import]) -> list[str]:
    """Imports that go past a face: a module that is not a package, or a name that the
    package's ``__all__`` does not publish."""
    exported: dict[str, list[str] | None] = {}
    bad = []
    for imp in imports:
        if not is_package(imp.module):
            bad.append(f"{imp.where}: {imp.module} is not a package: import from its package")
            continue
        path = module_path(imp.module)
        assert path is not None, imp
        names = exported.setdefault(imp.module, declared_all(path))
        for name in imp.names:
            if names is None or name not in names:
                bad.append(f"{imp.where}: {imp.module}.__all__ does not publish {name}")
    return bad


@dataclass(frozen=True)
class LazyFace:
    package: str
    typing_imports: frozenset[tuple[str, str]]  # (module, name) under ``if TYPE_CHECKING:``
    lazy: frozenset[tuple[str, str]]  # (module, name) of the lazy_exports map
    bound: frozenset[str]  # names the ``__init__`` binds when it runs
    all: tuple[str, ...]


def lazy_face(package: str) -> LazyFace | None:
    path = module_path(package)
    assert path is not None
    tree = ast.parse(path.read_text(encoding="utf-8"), filename=str(path))
    typing_imports: set[tuple[str, str]] = set()
    lazy: set[tuple[str, str]] = set()
    bound: set[str] = set()
    for node in tree.body:
        if isinstance(node, ast.If) and ast.unparse(node.test) == "TYPE_CHECKING":
            typing_imports |= {(sub.module or "", a.name) for sub in node.body
                               if isinstance(sub, ast.ImportFrom) for a in sub.names}
        elif isinstance(node, ast.If) and ast.unparse(node.test) == "not TYPE_CHECKING":
            for call in ast.walk(node):
                if isinstance(call, ast.Call) and ast.unparse(call.func) == "lazy_exports":
                    mapping = ast.literal_eval(call.args[1])
                    lazy |= {(module, name) for module, names in mapping.items() for name in names}
        elif isinstance(node, ast.ImportFrom | ast.Import):
            bound |= {(a.asname or a.name).split(".")[0] for a in node.names}
        elif isinstance(node, ast.FunctionDef | ast.ClassDef):
            bound.add(node.name)
        elif isinstance(node, ast.Assign):
            bound |= {n.id for t in node.targets for n in ast.walk(t) if isinstance(n, ast.Name)}
    if not lazy:
        return None
    return LazyFace(package, frozenset(typing_imports), frozenset(lazy), frozenset(bound),
                    tuple(declared_all(path) or ()))


def packages() -> list[str]:
    return sorted(".".join(p.parent.relative_to(ROOT).parts)
                  for top in PACKAGES for p in (ROOT / top).rglob("__init__.py"))


def used_subpackages() -> set[str]:
    return {imp.module for imp in cross_package_imports(PRODUCT)
            if "." in imp.module and is_package(imp.module)}


def listed_subpackages() -> set[str]:
    """The sub-packages of ARCHITECTURE.md's table (section "Public faces")."""
    text = (ROOT / "ARCHITECTURE.md").read_text(encoding="utf-8")
    section = text.split("## Public faces", 1)[1].split("\n## ", 1)[0]
    return {m["module"] for line in section.splitlines() if (m := TABLE_ROW.match(line))}


def test_imports_between_packages_name_a_package_and_a_published_name() -> None:
    imports = cross_package_imports(PRODUCT)
    assert len(imports) > 300  # the scan saw the real tree
    assert face_violations(imports) == []


def test_every_package_used_by_another_declares_its_public_names() -> None:
    faces = set(PACKAGES) | used_subpackages()
    assert sorted(p for p in faces if declared_all(ROOT.joinpath(*p.split("."), "__init__.py"))
                  is None) == []


def test_the_sub_packages_that_are_faces_are_those_the_table_lists() -> None:
    assert "simulator.world" in listed_subpackages()  # the table was found and read
    assert sorted(listed_subpackages() ^ used_subpackages()) == []


def test_lazy_maps_agree_with_type_checking_imports_and_all() -> None:
    faces = [face for p in packages() if (face := lazy_face(p)) is not None]
    assert {"contracts", "orchestrator", "service"} <= {f.package for f in faces}
    bad = []
    for f in faces:
        if f.lazy != f.typing_imports:
            bad.append(f"{f.package}: lazy map and TYPE_CHECKING imports differ by "
                       f"{sorted(f.lazy ^ f.typing_imports)}")
        names = [name for _, name in f.lazy]
        if unpublished := sorted(set(names) - set(f.all)):
            bad.append(f"{f.package}: lazy names missing from __all__: {unpublished}")
        if unbound := sorted(set(f.all) - set(names) - f.bound):
            bad.append(f"{f.package}: __all__ names bound nowhere: {unbound}")
        # a lazy name that is also a submodule must be that submodule (else the import system
        # may hand out the module where the face means the name)
        clashes = sorted(name for module, name in f.lazy if module != f.package
                         and module_path(f"{f.package}.{name}") is not None)
        if clashes:
            bad.append(f"{f.package}: lazy names that are also submodules: {clashes}")
    assert bad == []


LOOK_UP = """
import importlib, json, sys
wrong = []
for package in sys.argv[1:]:
    face = importlib.import_module(package)
    for name in face.__all__:
        try:
            getattr(face, name)
        except Exception as error:
            wrong.append(f"{package}.{name}: {error!r}")
print(json.dumps(wrong))
"""


def test_every_published_name_of_every_face_resolves() -> None:
    faces = sorted(set(PACKAGES) | used_subpackages())
    done = subprocess.run([sys.executable, "-c", LOOK_UP, *faces], cwd=ROOT, text=True,
                          capture_output=True, timeout=120, check=False)
    assert done.returncode == 0, done.stderr[-2000:]
    assert json.loads(done.stdout.strip().splitlines()[-1]) == []


def test_the_check_catches_imports_past_a_face() -> None:
    imports = [
        Import("a.py:1", "orchestrator.errors", ("ConfigError",)),
        Import("a.py:2", "orchestrator", ("ConfigError",)),
        Import("a.py:3", "orchestrator", ("NotAName",)),
        Import("a.py:4", "contracts", ("files",)),
        Import("a.py:5", "contracts", ("_private",)),
        Import("a.py:6", "contracts.files", ()),
        Import("a.py:7", "simulator.world", ("World",)),
    ]
    assert face_violations(imports) == [
        "a.py:1: orchestrator.errors is not a package: import from its package",
        "a.py:3: orchestrator.__all__ does not publish NotAName",
        "a.py:5: contracts.__all__ does not publish _private",
        "a.py:6: contracts.files is not a package: import from its package",
    ]
