"""JSON as Python values, for documents that are free JSON where they cross a boundary.

Use these only where the document really is arbitrary (a schema, an extra field a team may fill
as it likes, a payload passed through untouched); where the data has a shape, a ``TypedDict`` or
a dataclass says it better.
"""

from __future__ import annotations

import sys
from typing import Any, TypeAlias

JSONScalar: TypeAlias = str | int | float | bool | None
JSONValue: TypeAlias = JSONScalar | list["JSONValue"] | dict[str, "JSONValue"]
JSONObject: TypeAlias = dict[str, JSONValue]


class HugeInteger(str):
    """An integer written with more digits than Python reads into a number (its int-string
    limit, 4300 digits by default): kept as its text so that a reader of a file can name where
    it is (:func:`huge_integers`) instead of failing with a traceback."""


def parse_int(literal: str) -> int | HugeInteger:
    """An integer literal of a JSON or YAML file (``json.loads(..., parse_int=parse_int)``):
    its value, or :class:`HugeInteger`."""
    try:
        return int(literal)
    except ValueError:
        return HugeInteger(literal)


def int_digits_limit() -> int:
    """The most digits an integer may have to be read (Python's int-string limit)."""
    return sys.get_int_max_str_digits() or 4300


def huge_integers(value: Any, pointer: str = "") -> list[tuple[str, HugeInteger]]:
    """(JSON pointer, literal) of each :class:`HugeInteger` in a parsed document, keys too."""
    if isinstance(value, HugeInteger):
        return [(pointer, value)]
    found: list[tuple[str, HugeInteger]] = []
    if isinstance(value, dict):
        for key, item in value.items():
            at = f"{pointer}/{str(key).replace('~', '~0').replace('/', '~1')}"
            if isinstance(key, HugeInteger):
                found.append((at, key))
            found += huge_integers(item, at)
    elif isinstance(value, list):
        for index, item in enumerate(value):
            found += huge_integers(item, f"{pointer}/{index}")
    return found


def huge_integer_reason(literal: str) -> tuple[str, str]:
    """What is wrong with a :class:`HugeInteger` and what was expected, as two phrases."""
    digits = sum(ch.isdigit() for ch in literal)
    return (f"an integer of {digits} digits, too long to read",
            f"a number of at most {int_digits_limit()} digits")


__all__ = [
    "HugeInteger",
    "JSONObject",
    "JSONScalar",
    "JSONValue",
    "huge_integer_reason",
    "huge_integers",
    "parse_int",
]
