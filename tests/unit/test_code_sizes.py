"""Size caps of the product code: no class longer than :data:`CLASS_LINES` lines and no
function longer than :data:`FUNCTION_LINES` (a definition's lines from its ``def`` or
``class`` to its last line, docstring and comments included; a nested function counts in its
own right and inside the one around it).

The exceptions are listed with their size today and why they are still that long: an exception
may not grow past its listed size, and one that has come under the cap is taken off the list
(the test says so), so the list only shrinks."""

from __future__ import annotations

import ast
import functools
from collections.abc import Iterator
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
PRODUCT = ("hlvs", "viewer", "service", "envs", "tournament", "cluster", "orchestrator",
           "simulator", "referee", "robot", "contracts")
GENERATED = ("_pb2.py", "_pb2.pyi")

CLASS_LINES = 400
FUNCTION_LINES = 80

# "path::Qualified.name": (lines today, why)
LONG_CLASSES: dict[str, tuple[int, str]] = {
}
LONG_FUNCTIONS: dict[str, tuple[int, str]] = {}


@functools.cache
def _definitions() -> tuple[tuple[str, bool, int], ...]:
    """(``path::qualified name``, is a class, lines) of every class and function."""
    return tuple(_all())


def _all() -> Iterator[tuple[str, bool, int]]:
    for package in PRODUCT:
        for path in sorted((ROOT / package).rglob("*.py")):
            if path.name.endswith(GENERATED):
                continue
            rel = path.relative_to(ROOT).as_posix()
            tree = ast.parse(path.read_text(encoding="utf-8"), filename=rel)
            yield from _walk(tree, rel, "")


def _walk(node: ast.AST, rel: str, prefix: str) -> Iterator[tuple[str, bool, int]]:
    for child in ast.iter_child_nodes(node):
        if isinstance(child, ast.ClassDef | ast.FunctionDef | ast.AsyncFunctionDef):
            name = f"{prefix}{child.name}"
            assert child.end_lineno is not None
            yield (f"{rel}::{name}", isinstance(child, ast.ClassDef),
                   child.end_lineno - child.lineno + 1)
            yield from _walk(child, rel, f"{name}.")
        else:
            yield from _walk(child, rel, prefix)


def _over(classes: bool, cap: int, allowed: dict[str, tuple[int, str]]) -> list[str]:
    found = []
    for key, is_class, lines in _definitions():
        if is_class is not classes:
            continue
        limit = allowed[key][0] if key in allowed else cap
        if lines > limit:
            grown = " (listed: it may not grow)" if key in allowed else ""
            found.append(f"{key}: {lines} lines > {limit}{grown}")
    return found


def _stale(classes: bool, cap: int, allowed: dict[str, tuple[int, str]]) -> list[str]:
    sizes = {key: lines for key, is_class, lines in _definitions() if is_class is classes}
    stale = []
    for key in allowed:
        if key not in sizes:
            stale.append(f"{key}: no such definition any more")
        elif sizes[key] <= cap:
            stale.append(f"{key}: {sizes[key]} lines, under the cap of {cap}: take it off")
        elif sizes[key] < allowed[key][0]:
            stale.append(f"{key}: {sizes[key]} lines, listed as {allowed[key][0]}: lower it")
    return stale


def test_no_class_over_the_cap() -> None:
    assert _over(True, CLASS_LINES, LONG_CLASSES) == []


def test_no_function_over_the_cap() -> None:
    assert _over(False, FUNCTION_LINES, LONG_FUNCTIONS) == []


def test_the_exceptions_are_current() -> None:
    assert _stale(True, CLASS_LINES, LONG_CLASSES) == []
    assert _stale(False, FUNCTION_LINES, LONG_FUNCTIONS) == []


def test_the_walk_finds_methods_and_their_sizes() -> None:
    tree = ast.parse("class A:\n    def f(self):\n        x = 1\n        return x\n")
    assert list(_walk(tree, "m.py", "")) == [("m.py::A", True, 4), ("m.py::A.f", False, 3)]
