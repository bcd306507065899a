"""JSON as Python values, for documents that are free JSON where they cross a boundary.

Use these only where the document really is arbitrary (a schema, an extra field a team may fill
as it likes, a payload passed through untouched); where the data has a shape, a ``TypedDict`` or
a dataclass says it better.
"""

from __future__ import annotations

from typing import TypeAlias

JSONScalar: TypeAlias = str | int | float | bool | None
JSONValue: TypeAlias = JSONScalar | list["JSONValue"] | dict[str, "JSONValue"]
JSONObject: TypeAlias = dict[str, JSONValue]

__all__ = ["JSONObject", "JSONScalar", "JSONValue"]
