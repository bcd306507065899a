"""JSON Schema validation (draft 2020-12) with errors turned into precise problem lines.

The schemas ship inside the package (``orchestrator/config/schemas/``); ``configs/schemas/``
links to the same files.
"""

from __future__ import annotations

import json
from functools import cache
from importlib import resources
from typing import Any

from jsonschema import Draft202012Validator
from jsonschema.exceptions import ValidationError

from contracts import JSONObject
from orchestrator.config.jsonfile import json_type
from orchestrator.config.problems import Collector, one_of, pointer, suggest

SCHEMA_FILES = {"game": "game.schema.json", "team": "team_config.schema.json"}

# What a value matching a "pattern" looks like, by the name of the field.
_PATTERN_EXPECTED = {
    "record_simulation": "a path ending in .html or .mp4",
    "match_id": "letters, digits, '_', '.', '-' (at most 64, starting with a letter or digit)",
    "image": "an image repository without tag, e.g. 127.0.0.1:5000/team-a/robot",
    "dockerTag": "a Docker tag: letters, digits, '_', '.', '-' (at most 128)",
    "password_env": "an environment variable name",
    "region": "an AWS region, e.g. us-east-1",
    "players": 'player numbers "1".."N"',
}
_ONE_OF_EXPECTED = {
    "id": "an integer 0-255 (a string of digits is accepted)",
    "registry_auth": (
        'one of {"username", "password"}, {"username", "password_env"}, '
        '{"ecr": {"region", "access_id"?, "access_secret"?}}'
    ),
}


@cache
def load_schema(kind: str) -> JSONObject:
    text = (
        resources.files("orchestrator.config.schemas")
        .joinpath(SCHEMA_FILES[kind])
        .read_text(encoding="utf-8")
    )
    schema: JSONObject = json.loads(text)
    return schema


@cache
def _validator(kind: str) -> Draft202012Validator:
    schema = load_schema(kind)
    Draft202012Validator.check_schema(schema)
    return Draft202012Validator(schema, format_checker=Draft202012Validator.FORMAT_CHECKER)


def validate(kind: str, document: Any, where: Collector) -> bool:
    """Add one problem per schema violation to ``where``; True when the document is valid."""
    before = len(where.errors)
    errors = sorted(_validator(kind).iter_errors(document), key=_sort_key)
    found = Collector(where.file)
    for error in errors:
        _translate(error, found)
    seen: set[tuple[str, str]] = set()
    for problem in found.problems:
        if (problem.pointer, problem.message) not in seen:
            seen.add((problem.pointer, problem.message))
            where.problems.append(problem)
    return len(where.errors) == before


def _sort_key(error: ValidationError) -> tuple[str, str]:
    return (pointer(*error.absolute_path), str(error.validator))


def _translate(error: ValidationError, where: Collector) -> None:
    path = list(error.absolute_path)
    at = pointer(*path)
    name = str(path[-1]) if path else ""
    keyword = str(error.validator)
    value = error.validator_value
    instance = error.instance
    schema = error.schema if isinstance(error.schema, dict) else {}
    if "propertyNames" in error.schema_path:
        where.error(
            pointer(*path, str(instance)),
            f"invalid key {_show(instance)}",
            expected=_PATTERN_EXPECTED.get(name, "a valid key"),
        )
    elif keyword == "required":
        present = instance if isinstance(instance, dict) else {}
        for key in value:
            if key not in present:
                where.error(pointer(*path, key), "required field is missing")
    elif keyword == "additionalProperties":
        allowed = sorted(schema.get("properties", {}))
        for key in sorted(instance):
            if key in allowed:
                continue
            if not allowed:  # a map (players): the value itself is checked elsewhere
                continue
            hint = suggest(key, allowed)
            where.error(
                pointer(*path, key),
                f'unknown field "{key}"',
                expected=one_of(allowed) if not hint else "",
                suggestion=hint,
            )
    elif keyword == "enum":
        hint = suggest(str(instance), [str(v) for v in value]) if isinstance(instance, str) else ""
        where.error(at, f"invalid value {_show(instance)}", expected=one_of(value), suggestion=hint)
    elif keyword == "type":
        where.error(at, f"wrong type: {json_type(instance)}", expected=_type_name(value))
    elif keyword == "format":
        where.error(at, f"{_show(instance)} is not an IPv4 address", expected="an IPv4 address")
    elif keyword == "pattern":
        expected = _PATTERN_EXPECTED.get(name, f"a string matching {value}")
        where.error(at, f"invalid value {_show(instance)}", expected=expected)
    elif keyword in ("minItems", "maxItems"):
        where.error(at, f"{len(instance)} items", expected=_items_expected(schema))
    elif keyword == "minLength":
        where.error(at, "must not be empty")
    elif keyword == "maxLength":
        where.error(at, f"{len(instance)} characters: {_show(instance)}",
                    expected=f"at most {value} characters")
    elif keyword in ("minimum", "maximum", "exclusiveMinimum", "exclusiveMaximum"):
        where.error(at, f"{_show(instance)} is out of range", expected=_range_expected(schema))
    elif keyword == "oneOf":
        key = name if name in _ONE_OF_EXPECTED else ""
        where.error(
            at,
            f"invalid value {_show(instance)}",
            expected=_ONE_OF_EXPECTED.get(key, "a value allowed by the schema"),
        )
    else:
        where.error(at, error.message)


def _show(value: Any) -> str:
    text = json.dumps(value)
    return text if len(text) <= 60 else text[:57] + "..."


def _type_name(value: Any) -> str:
    names = {
        "object": "an object",
        "array": "an array",
        "string": "a string",
        "number": "a number",
        "integer": "an integer",
        "boolean": "true or false",
        "null": "null",
    }
    if isinstance(value, list):
        return " or ".join(names.get(str(v), str(v)) for v in value)
    return names.get(str(value), str(value))


def _items_expected(schema: dict[str, Any]) -> str:
    low, high = schema.get("minItems"), schema.get("maxItems")
    kind = _type_name(schema.get("items", {}).get("type", "value")).removeprefix("a ")
    kind = kind.removeprefix("an ")
    if low is not None and low == high:
        return f"{low} {kind}s"
    if high is None:
        return f"at least {low} {kind}{'s' if low != 1 else ''}"
    return f"{low or 0} to {high} {kind}s"


def _range_expected(schema: dict[str, Any]) -> str:
    parts = []
    if "minimum" in schema:
        parts.append(f">= {schema['minimum']}")
    if "exclusiveMinimum" in schema:
        parts.append(f"> {schema['exclusiveMinimum']}")
    if "maximum" in schema:
        parts.append(f"<= {schema['maximum']}")
    if "exclusiveMaximum" in schema:
        parts.append(f"< {schema['exclusiveMaximum']}")
    return "a number " + " and ".join(parts)
