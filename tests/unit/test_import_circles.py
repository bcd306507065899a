"""No import circle in the product, counting every import: at the top of a module, under
``TYPE_CHECKING`` and inside functions (a function-level import hides a circle from Python,
not from the design). The graph is built with ``ast`` over the product packages and the tools
(``benchmarks``, ``testkit``); an import through a package's face counts as an import of the
module that defines the name (the face's lazy map or its own imports say which), and a face
importing its own modules is not a circle. Circles are looked for at three levels: between
top-level packages (``hlvs`` and ``benchmarks``), between the parts of a package (its
sub-packages and modules: ``orchestrator.engine`` and ``orchestrator.match``), and between
modules.

A circle that has to stay a while would be listed in :data:`KNOWN` with the reason (none is);
a circle found outside it, or larger than listed, fails the test with the imports that close it
(``file:line``)."""

from __future__ import annotations

import ast
import copy
import functools
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
PACKAGES = ("hlvs", "viewer", "service", "envs", "tournament", "cluster", "orchestrator",
            "simulator", "referee", "robot", "contracts", "benchmarks", "testkit")

# Circles still allowed, each with the reason it cannot be broken yet (none today).
KNOWN: dict[str, frozenset[str]] = {}


@dataclass
class Graph:
    modules: dict[str, Path] = field(default_factory=dict)
    edges: dict[str, set[str]] = field(default_factory=dict)
    where: dict[tuple[str, str], str] = field(default_factory=dict)  # edge -> file:line


def _module_name(path: Path) -> str:
    parts = path.relative_to(ROOT).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def _face_names(name: str, tree: ast.Module) -> dict[str, str]:
    """Name -> defining module, for a package's ``__init__``: its lazy map and its imports."""
    names: dict[str, str] = {}
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            for alias in node.names:
                names.setdefault(alias.asname or alias.name, node.module)
        elif isinstance(node, ast.Call) and getattr(node.func, "id", "") == "lazy_exports" \
                and len(node.args) == 2 and isinstance(node.args[1], ast.Dict):
            for key, value in zip(node.args[1].keys, node.args[1].values, strict=True):
                if isinstance(key, ast.Constant) and isinstance(value, ast.Tuple | ast.List):
                    for item in value.elts:
                        if isinstance(item, ast.Constant):
                            names[str(item.value)] = str(key.value)
    return names


@functools.cache
def build() -> Graph:
    """The graph of the tree as it is (built once; a test that changes it works on a copy)."""
    graph = Graph()
    trees: dict[str, ast.Module] = {}
    for package in PACKAGES:
        for path in sorted((ROOT / package).rglob("*.py")):
            name = _module_name(path)
            graph.modules[name] = path
            trees[name] = ast.parse(path.read_text(encoding="utf-8"), filename=str(path))
    faces = {name: _face_names(name, trees[name]) for name, path in graph.modules.items()
             if path.name == "__init__.py"}

    def owner(module: str) -> str | None:
        while module and module not in graph.modules:
            module = module.rpartition(".")[0]
        return module or None

    def resolve(module: str, name: str, seen: frozenset[str] = frozenset()) -> str | None:
        """The module that ``from module import name`` reaches."""
        if f"{module}.{name}" in graph.modules:
            return f"{module}.{name}"
        target = faces.get(module, {}).get(name)
        if target is None or target == module or module in seen:
            return owner(module)
        if target in faces:  # re-exported from a sub-package's face
            return resolve(target, name, seen | {module})
        return owner(target)

    for name, tree in trees.items():
        path = graph.modules[name]
        package = name if path.name == "__init__.py" else name.rpartition(".")[0]
        targets: set[str] = set()
        for node in ast.walk(tree):
            found: list[str | None] = []
            if isinstance(node, ast.Import):
                found = [owner(alias.name) for alias in node.names
                         if alias.name.split(".")[0] in PACKAGES]
            elif isinstance(node, ast.ImportFrom):
                base = node.module or ""
                if node.level:
                    anchor = package.split(".")[: len(package.split(".")) - node.level + 1]
                    base = ".".join([*anchor, *([base] if base else [])])
                if base.split(".")[0] not in PACKAGES:
                    continue
                found = [resolve(base, alias.name) for alias in node.names]
            for target in found:
                if target is None or target == name:
                    continue
                if path.name == "__init__.py" and target.startswith(name + "."):
                    continue  # a face importing its own modules
                targets.add(target)
                graph.where.setdefault((name, target),
                                       f"{path.relative_to(ROOT)}:{node.lineno}")
        graph.edges[name] = targets
    return graph


def unit(module: str, depth: int) -> str:
    return ".".join(module.split(".")[:depth])


def circles(graph: Graph, depth: int | None) -> list[set[str]]:
    """The strongly connected components of more than one node, the modules grouped to their
    first ``depth`` name parts (None: modules)."""
    nodes: dict[str, set[str]] = {}
    for source, targets in graph.edges.items():
        a = source if depth is None else unit(source, depth)
        nodes.setdefault(a, set())
        for target in targets:
            b = target if depth is None else unit(target, depth)
            if a != b:
                nodes[a].add(b)
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    found: list[set[str]] = []

    def connect(v: str) -> None:  # Tarjan
        index[v] = low[v] = len(index)
        stack.append(v)
        on_stack.add(v)
        for w in sorted(nodes.get(v, ())):
            if w not in index:
                connect(w)
                low[v] = min(low[v], low[w])
            elif w in on_stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            component = set()
            while True:
                w = stack.pop()
                on_stack.discard(w)
                component.add(w)
                if w == v:
                    break
            if len(component) > 1:
                found.append(component)

    for v in sorted(nodes):
        if v not in index:
            connect(v)
    return found


def closing_imports(graph: Graph, component: set[str], depth: int | None) -> Iterator[str]:
    for (source, target), where in sorted(graph.where.items()):
        a = source if depth is None else unit(source, depth)
        b = target if depth is None else unit(target, depth)
        if a != b and a in component and b in component:
            yield f"{where}: {source} -> {target}"


def unexplained(graph: Graph) -> list[str]:
    problems = []
    for depth in (1, 2, None):
        for component in circles(graph, depth):
            if any(component <= known for known in KNOWN.values()):
                continue
            level = {1: "packages", 2: "parts of a package", None: "modules"}[depth]
            problems.append(f"circle between {level} {sorted(component)}:\n  "
                            + "\n  ".join(closing_imports(graph, component, depth)))
    return problems


def test_no_import_circle_outside_the_known_ones() -> None:
    graph = build()
    assert len(graph.modules) > 300 and "orchestrator.engine.containers" in graph.modules
    assert unexplained(graph) == []


def test_function_level_and_face_imports_count() -> None:
    """The graph sees an import inside a function, one under TYPE_CHECKING and one through a
    lazy face."""
    graph = build()
    # inside a function, through the lazy face of `orchestrator`: the module that defines it
    assert "orchestrator.scrimmage_options" in graph.edges["benchmarks.short_match"]
    assert "orchestrator.signals" in graph.edges["benchmarks.scrimmage"]
    # under TYPE_CHECKING
    assert "simulator.world.look" in graph.edges["simulator.replay.format"]
    # a face's own modules are not edges of the face
    assert not any(t.startswith("orchestrator.") for t in graph.edges["orchestrator"])


def test_the_check_finds_a_circle_made_of_function_level_imports() -> None:
    graph = copy.deepcopy(build())
    graph.edges["referee"] = {*graph.edges["referee"], "simulator.render"}
    graph.where[("referee", "simulator.render")] = "referee/__init__.py:1"
    problems = unexplained(graph)
    assert problems and "circle between packages" in problems[0]
    assert "referee/__init__.py:1: referee -> simulator.render" in problems[0]


def test_the_known_circles_are_still_there() -> None:
    """A known circle that is gone leaves the list (so that it cannot come back unnoticed)."""
    graph = build()
    modules = circles(graph, None)
    for name, known in KNOWN.items():
        assert any(c & known for c in modules), f"{name}: no circle any more, remove it"
