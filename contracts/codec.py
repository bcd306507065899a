"""JSON for frozen dataclasses: one reader and one writer for every contract type.

:func:`to_data` turns a dataclass into JSON values (enums by value, tuples as lists);
:func:`from_data` builds one from JSON values, checking each field against its type hint and
naming the field (as a JSON pointer) when something does not fit. :class:`Versioned` adds
``to_json`` / ``from_json`` / ``load`` with a ``version`` check to a top-level contract.
"""

from __future__ import annotations

import json
import types
from dataclasses import MISSING, Field, fields, is_dataclass
from enum import Enum
from pathlib import Path
from typing import (
    Any,
    ClassVar,
    Literal,
    TypeVar,
    Union,
    get_args,
    get_origin,
    get_type_hints,
    is_typeddict,
)

from contracts.errors import ContractError, UnknownVersion
from contracts.jsontypes import JSONObject

T = TypeVar("T")
V = TypeVar("V", bound="Versioned")


JSON_KEY = "json_key"
"""Field metadata: the field's key in JSON when it cannot be its Python name (``class``)."""


OMIT_NONE = "omit_none"
"""Field metadata: the key is left out of the JSON while the field is None."""


def json_key(key: str) -> dict[str, str]:
    """``field(metadata=json_key("class"))``: the field is written and read as ``key``."""
    return {JSON_KEY: key}


def omitted_when_none() -> dict[str, bool]:
    """``field(default=None, metadata=omitted_when_none())``: no key while the value is None."""
    return {OMIT_NONE: True}


def _key(f: Field[Any]) -> str:
    return str(f.metadata.get(JSON_KEY, f.name))


def to_data(value: Any) -> Any:
    """JSON values for a dataclass (recursively); enums become their values, tuples lists."""
    if is_dataclass(value) and not isinstance(value, type):
        return {
            _key(f): to_data(getattr(value, f.name))
            for f in fields(value)
            if not (f.metadata.get(OMIT_NONE) and getattr(value, f.name) is None)
        }
    if isinstance(value, Enum):
        return value.value
    if isinstance(value, tuple | list):
        return [to_data(item) for item in value]
    if isinstance(value, dict):
        return {str(to_data(key)): to_data(item) for key, item in value.items()}
    return value


def from_data(cls: type[T], data: Any, *, source: str, pointer: str = "") -> T:
    """An instance of dataclass ``cls`` from JSON values; :class:`ContractError` names the field."""
    if not isinstance(data, dict):
        raise ContractError(source=source, pointer=pointer, reason="expected an object")
    hints = get_type_hints(cls)
    keys = {_key(f): f.name for f in fields(cls) if f.init}  # type: ignore[arg-type]
    unknown = sorted(set(data) - set(keys))
    if unknown:
        raise ContractError(
            source=source, pointer=f"{pointer}/{unknown[0]}", reason="unknown field"
        )
    for f in fields(cls):  # type: ignore[arg-type]
        required = f.default is MISSING and f.default_factory is MISSING
        if f.init and required and _key(f) not in data:
            raise ContractError(
                source=source, pointer=f"{pointer}/{_key(f)}", reason="missing field"
            )
    kwargs = {
        name: convert(hints[name], data[key], source=source, pointer=f"{pointer}/{key}")
        for key, name in keys.items()
        if key in data
    }
    try:
        return cls(**kwargs)
    except (TypeError, ValueError) as exc:
        raise ContractError(source=source, pointer=pointer, reason=str(exc)) from exc


def convert(hint: Any, value: Any, *, source: str, pointer: str) -> Any:
    """``value`` checked against (and converted to) the type ``hint``."""
    origin = get_origin(hint)
    args = get_args(hint)
    if hint is Any or hint is object:
        return value
    if is_dataclass(hint):
        return from_data(hint, value, source=source, pointer=pointer)  # type: ignore[arg-type]
    if is_typeddict(hint):  # a JSON object of a documented shape: checked as an object only
        return convert(dict[str, Any], value, source=source, pointer=pointer)
    if isinstance(hint, type) and issubclass(hint, Enum):
        try:
            return hint(value)
        except ValueError:
            allowed = [member.value for member in hint]
            raise ContractError(
                source=source, pointer=pointer, reason=f"expected one of {allowed}"
            ) from None
    if origin is tuple:
        if not isinstance(value, list | tuple):
            raise ContractError(source=source, pointer=pointer, reason="expected a list")
        if len(args) == 2 and args[1] is Ellipsis:
            item_hints = [args[0]] * len(value)
        else:
            if len(args) != len(value):
                raise ContractError(
                    source=source, pointer=pointer, reason=f"expected {len(args)} items"
                )
            item_hints = list(args)
        return tuple(
            convert(h, v, source=source, pointer=f"{pointer}/{i}")
            for i, (h, v) in enumerate(zip(item_hints, value, strict=True))
        )
    if origin is dict:
        if not isinstance(value, dict):
            raise ContractError(source=source, pointer=pointer, reason="expected an object")
        key_hint, item_hint = args or (str, Any)
        return {
            convert(key_hint, k, source=source, pointer=f"{pointer}/{k}"): convert(
                item_hint, v, source=source, pointer=f"{pointer}/{k}"
            )
            for k, v in value.items()
        }
    if origin is Literal:
        if value not in args:
            raise ContractError(
                source=source, pointer=pointer, reason=f"expected one of {list(args)}"
            )
        return value
    if origin in (Union, types.UnionType):
        if value is None and type(None) in args:
            return None
        inner = [a for a in args if a is not type(None)]
        if len(inner) == 1:
            return convert(inner[0], value, source=source, pointer=pointer)
        for option in inner:
            try:
                return convert(option, value, source=source, pointer=pointer)
            except ContractError:
                continue
        raise ContractError(source=source, pointer=pointer, reason=f"expected {hint}")
    if hint is float:
        if isinstance(value, bool) or not isinstance(value, int | float):
            raise ContractError(source=source, pointer=pointer, reason="expected a number")
        return float(value)
    if hint in (int, str, bool):
        if not isinstance(value, hint) or (hint is int and isinstance(value, bool)):
            raise ContractError(source=source, pointer=pointer, reason=f"expected {hint.__name__}")
        return value
    return value


class Versioned:
    """Mixin of a top-level contract (a frozen dataclass with a ``version: int`` field).

    ``from_json`` reads a document of this build's ``VERSION`` (a document without ``version``
    counts as version 1, the first one written) and rejects any other with
    :class:`~contracts.errors.UnknownVersion`.
    """

    VERSION: ClassVar[int] = 1
    KIND: ClassVar[str] = "document"
    FILE_MODE: ClassVar[int | None] = None  # permissions of a written file (None: the umask's)

    def to_dict(self) -> JSONObject:
        data: JSONObject = to_data(self)
        return data

    def to_json(self, *, indent: int | None = 2) -> str:
        return json.dumps(self.to_dict(), indent=indent, sort_keys=True)

    @classmethod
    def from_dict(cls: type[V], data: Any, *, source: str = "<json>") -> V:
        if not isinstance(data, dict):
            raise ContractError(source=source, pointer="", reason="expected a JSON object")
        version = data.get("version", 1)
        if version != cls.VERSION:
            raise UnknownVersion(source=source, kind=cls.KIND, version=version, known=cls.VERSION)
        return from_data(cls, data, source=source)

    @classmethod
    def from_json(cls: type[V], text: str | bytes, *, source: str = "<json>") -> V:
        try:
            data = json.loads(text)
        except ValueError as exc:
            raise ContractError(source=source, pointer="", reason=f"not JSON: {exc}") from exc
        return cls.from_dict(data, source=source)

    @classmethod
    def load(cls: type[V], path: str | Path) -> V:
        path = Path(path)
        try:
            text = path.read_text(encoding="utf-8")
        except OSError as exc:
            raise ContractError(source=str(path), pointer="", reason=f"cannot read: {exc}") from exc
        return cls.from_json(text, source=str(path))

    def write(self, path: str | Path) -> Path:
        """Write atomically (a temporary file renamed into place), with :attr:`FILE_MODE`."""
        path = Path(path)
        path.parent.mkdir(parents=True, exist_ok=True)
        tmp = path.with_name(path.name + ".tmp")
        tmp.write_text(self.to_json() + "\n", encoding="utf-8")
        if self.FILE_MODE is not None:
            tmp.chmod(self.FILE_MODE)
        tmp.replace(path)
        return path


__all__ = [
    "JSON_KEY",
    "OMIT_NONE",
    "Versioned",
    "convert",
    "from_data",
    "json_key",
    "omitted_when_none",
    "to_data",
]
