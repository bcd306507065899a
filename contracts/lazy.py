"""Lazy public faces (PEP 562): a package publishes names of its submodules without importing
them until they are first used, so that importing the package stays cheap.

A package's ``__init__`` lists the names under ``if TYPE_CHECKING:`` (so that type checkers and
editors see the real objects), declares them in ``__all__`` and hands the same map to
:func:`lazy_exports`::

    if TYPE_CHECKING:
        from orchestrator.paths import absolute_path

    __all__ = ["absolute_path"]

    if not TYPE_CHECKING:
        __getattr__, __dir__ = lazy_exports(__name__, {
            "orchestrator.paths": ("absolute_path",),
        })

A map entry whose module is the package itself publishes submodules by name (a module used as a
namespace, such as ``contracts.files``). Standard library only: every process imports it.
"""

from __future__ import annotations

import sys
from collections.abc import Callable, Mapping


def lazy_exports(
    package: str, exports: Mapping[str, tuple[str, ...]]
) -> tuple[Callable[[str], object], Callable[[], list[str]]]:
    """The module ``__getattr__`` and ``__dir__`` of ``package``, which publishes each name of
    ``exports[module]`` from ``module``: the module is imported on the name's first use, and
    each use reads the name from it (so a test's patch of the module shows through the face)."""
    where: dict[str, str] = {}
    for module, names in exports.items():
        for name in names:
            if name in where:
                raise ValueError(f"{package}: {name!r} is exported by {where[name]} and {module}")
            where[name] = module

    def __getattr__(name: str) -> object:
        module = where.get(name)
        if module is None:
            raise AttributeError(f"module {package!r} has no attribute {name!r}")
        if module == package:
            return _load(f"{package}.{name}")
        # not kept in the package: each lookup reads the module, where a test may patch it
        return getattr(_load(module), name)

    def __dir__() -> list[str]:
        return sorted(set(vars(sys.modules[package])) | set(where))

    return __getattr__, __dir__


def _load(module: str) -> object:
    """``module``, imported through ``__import__`` (``python -X importtime`` sees the import,
    which it does not where ``importlib.import_module`` makes it)."""
    __import__(module)
    return sys.modules[module]
