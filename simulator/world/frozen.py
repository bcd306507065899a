"""Building frozen slotted dataclasses without their generated ``__init__``.

A frozen dataclass's ``__init__`` sets each field with ``object.__setattr__`` (its own
``__setattr__`` refuses), which costs about 1.5 us for the twelve fields of a
:class:`referee.snapshot.RobotState`; a snapshot of eight robots is built every 8 ms step.
:func:`slot_constructor` makes a keyword-only function that creates the same object by calling
each slot's descriptor directly (about 0.7 us). The result is an instance of the class itself
with every field set, so equality, hashing, ``repr`` and pickling are the dataclass's own.

Only for dataclasses that do nothing in ``__init__`` but store their fields: frozen, slotted,
every field in ``__init__``, no ``__post_init__``; anything else is refused.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from typing import Any, TypeVar

T = TypeVar("T")


def slot_constructor(cls: type[T], *, positional: bool = False) -> Callable[..., T]:
    """A function ``make(*, field=value, ...)`` taking every field of ``cls`` by keyword (no
    defaults) and returning an instance equal to ``cls(field=value, ...)``; with
    ``positional``, ``make(value, ...)`` takes them in the order of the class's fields (for
    ``map`` over columns of values)."""
    params = getattr(cls, "__dataclass_params__", None)
    if params is None or not params.frozen:
        raise TypeError(f"{cls.__name__} is not a frozen dataclass")
    fields = dataclasses.fields(cls)  # type: ignore[arg-type]
    names = [f.name for f in fields]
    if tuple(getattr(cls, "__slots__", ())) != tuple(names):
        raise TypeError(f"{cls.__name__} is not slotted with exactly its fields")
    if hasattr(cls, "__post_init__") or not all(f.init for f in fields):
        raise TypeError(f"{cls.__name__} does more than store its fields in __init__")
    namespace: dict[str, Any] = {"_new": object.__new__, "_cls": cls}
    star = "" if positional else "*, "
    lines = [f"def make({star}{', '.join(names)}):", "    obj = _new(_cls)"]
    for i, name in enumerate(names):
        namespace[f"_set{i}"] = cls.__dict__[name].__set__  # the slot's member descriptor
        lines.append(f"    _set{i}(obj, {name})")
    lines.append("    return obj")
    exec("\n".join(lines), namespace)  # noqa: S102 -- source built from field names only
    make: Callable[..., T] = namespace["make"]
    make.__qualname__ = make.__name__ = f"make_{cls.__name__}"
    return make
