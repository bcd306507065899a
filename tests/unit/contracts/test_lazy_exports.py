"""contracts.lazy_exports: a package's names are imported on first use, from their module."""

from __future__ import annotations

import sys
from collections.abc import Iterator
from pathlib import Path

import pytest

from contracts import lazy_exports

FACE = '''
from contracts import lazy_exports

__all__ = ["VALUE", "helpers", "twice"]
__getattr__, __dir__ = lazy_exports(__name__, {
    "lazyfacepkg.numbers": ("VALUE", "twice"),
    "lazyfacepkg": ("helpers",),
})
'''


@pytest.fixture
def package(tmp_path: Path) -> Iterator[str]:
    root = tmp_path / "lazyfacepkg"
    root.mkdir()
    (root / "__init__.py").write_text(FACE, encoding="utf-8")
    (root / "numbers.py").write_text("VALUE = 7\n\ndef twice(x):\n    return 2 * x\n",
                                     encoding="utf-8")
    (root / "helpers.py").write_text("NAME = 'helpers'\n", encoding="utf-8")
    sys.path.insert(0, str(tmp_path))
    yield "lazyfacepkg"
    sys.path.remove(str(tmp_path))
    for name in [m for m in sys.modules if m.split(".")[0] == "lazyfacepkg"]:
        del sys.modules[name]


def test_a_name_is_imported_from_its_module_on_first_use(package: str) -> None:
    face = __import__(package)
    assert f"{package}.numbers" not in sys.modules  # importing the face imported nothing
    assert face.VALUE == 7
    assert f"{package}.numbers" in sys.modules
    from lazyfacepkg import twice

    assert twice(3) == 6


def test_a_published_submodule_is_the_module(package: str) -> None:
    from lazyfacepkg import helpers

    assert helpers is sys.modules[f"{package}.helpers"]
    assert helpers.NAME == "helpers"


def test_each_lookup_reads_the_module_so_a_patch_of_it_shows(
    package: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    face = __import__(package)
    assert face.VALUE == 7
    monkeypatch.setattr(f"{package}.numbers.VALUE", 8)
    assert face.VALUE == 8


def test_an_unknown_name_is_an_attribute_error(package: str) -> None:
    face = __import__(package)
    with pytest.raises(AttributeError, match="'lazyfacepkg' has no attribute 'MISSING'"):
        face.MISSING  # noqa: B018
    with pytest.raises(ImportError):
        from lazyfacepkg import MISSING  # noqa: F401
    assert {"VALUE", "helpers", "twice"} <= set(dir(face))


def test_a_name_from_two_modules_is_refused() -> None:
    with pytest.raises(ValueError, match="'X' is exported by p.a and p.b"):
        lazy_exports("p", {"p.a": ("X",), "p.b": ("X",)})
