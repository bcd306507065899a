"""Reading a JSON file into Python values with one clean problem line for every failure."""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

from contracts import JSONObject, huge_integer_reason, huge_integers, parse_int
from orchestrator.config.problems import Collector
from orchestrator.errors import ConfigError, Problem

MAX_FILE_BYTES = 16 * 1024 * 1024


def huge_integer_problems(value: Any, *, file: str) -> list[Problem]:
    """A problem for each integer too long to read (:class:`contracts.jsontypes.HugeInteger`)
    in a parsed document, at its JSON pointer."""
    problems = []
    for pointer, literal in huge_integers(value):
        message, expected = huge_integer_reason(literal)
        problems.append(Problem(file, pointer, message, expected=expected))
    return problems


def read_text(path: Path) -> str:
    """The UTF-8 text of a configuration file; ConfigError for anything that is not one."""
    where = Collector(str(path))
    try:
        if path.is_dir():
            where.error("", "is a directory", expected="a file")
            raise ConfigError(where.problems)
        if path.exists() and not path.is_file():
            where.error("", "not a regular file", expected="a file")
            raise ConfigError(where.problems)
        with path.open("rb") as stream:
            data = stream.read(MAX_FILE_BYTES + 1)
    except FileNotFoundError:
        where.error("", "file not found")
        raise ConfigError(where.problems) from None
    except PermissionError:
        where.error("", "permission denied")
        raise ConfigError(where.problems) from None
    except OSError as exc:
        where.error("", f"cannot read: {exc.strerror or exc}")
        raise ConfigError(where.problems) from None
    if len(data) > MAX_FILE_BYTES:
        where.error("", "file is too large", expected=f"at most {MAX_FILE_BYTES} bytes")
        raise ConfigError(where.problems)
    if not data.strip():
        where.error("", "file is empty", expected="a JSON object")
        raise ConfigError(where.problems)
    if b"\x00" in data:
        where.error("", "binary file", expected="a UTF-8 text file")
        raise ConfigError(where.problems)
    try:
        return data.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        where.error("", f"not UTF-8 text (byte {exc.start})", expected="a UTF-8 text file")
        raise ConfigError(where.problems) from None


def parse_json(text: str, *, file: str) -> Any:
    """Parse JSON text; invalid JSON becomes a problem with line and column."""
    try:
        value = json.loads(text, parse_constant=_reject_constant, parse_float=_finite_float,
                           parse_int=parse_int)
    except json.JSONDecodeError as exc:
        where = Collector(file)
        where.error("", f"invalid JSON at line {exc.lineno} column {exc.colno}: {exc.msg}")
        raise ConfigError(where.problems) from None
    except _NonStandardNumber as exc:
        where = Collector(file)
        where.error("", f"invalid JSON: {exc.constant} is not a finite number")
        raise ConfigError(where.problems) from None
    except RecursionError:
        where = Collector(file)
        where.error("", "invalid JSON: nested too deeply")
        raise ConfigError(where.problems) from None
    huge = huge_integer_problems(value, file=file)
    if huge:
        raise ConfigError(huge)
    duplicates = duplicate_keys(text)
    if duplicates:
        where = Collector(file)
        for at, key, first, second in duplicates:
            where.error(at, f"key {json.dumps(key)} appears twice: at line {first} and at line "
                        f"{second} (JSON readers keep only one of them)",
                        expected="each key once per object")
        raise ConfigError(where.problems)
    return value


def duplicate_keys(text: str) -> list[tuple[str, str, int, int]]:
    """Keys repeated within one object of valid JSON ``text``: (pointer of the object, key,
    line of the first, line of the repeat)."""
    found: list[tuple[str, str, int, int]] = []
    # stack entries: [pointer, keys seen (key -> line) or None for an array, expecting a key,
    #                 the current key or array index]
    stack: list[list[Any]] = []
    line, i, n = 1, 0, len(text)

    def child() -> str:
        if not stack:
            return ""
        top = stack[-1]
        part = str(top[3]).replace("~", "~0").replace("/", "~1")
        return f"{top[0]}/{part}"

    while i < n:
        c = text[i]
        if c == "\n":
            line += 1
        elif c == '"':
            j, start_line = i + 1, line
            chars: list[str] = []
            while text[j] != '"':
                if text[j] == "\\":
                    chars.append(text[j:j + 2])
                    j += 2
                    continue
                chars.append(text[j])
                j += 1
            raw = '"' + "".join(chars) + '"'
            if stack and stack[-1][1] is not None and stack[-1][2]:
                key = json.loads(raw)
                top = stack[-1]
                if key in top[1]:
                    found.append((top[0], key, top[1][key], start_line))
                else:
                    top[1][key] = start_line
                top[2], top[3] = False, key
            i = j
        elif c in "{[":
            pointer = child()
            stack.append([pointer, {} if c == "{" else None, c == "{", 0])
        elif c in "}]":
            stack.pop()
        elif c == "," and stack:
            top = stack[-1]
            if top[1] is not None:
                top[2] = True
            else:
                top[3] += 1
        i += 1
    return found


def read_json(path: Path) -> Any:
    return parse_json(read_text(path), file=str(path))


def read_json_object(path: Path) -> JSONObject:
    value = read_json(path)
    if not isinstance(value, dict):
        where = Collector(str(path))
        where.error("", f"the top level is {json_type(value)}", expected="a JSON object")
        raise ConfigError(where.problems)
    return value


def json_type(value: Any) -> str:
    if value is None:
        return "null"
    if isinstance(value, bool):
        return "a boolean"
    if isinstance(value, int | float):
        return "a number"
    if isinstance(value, str):
        return "a string"
    if isinstance(value, list):
        return "an array"
    return "an object"


class _NonStandardNumber(ValueError):
    def __init__(self, constant: str) -> None:
        self.constant = constant
        super().__init__(constant)


def _reject_constant(constant: str) -> Any:
    raise _NonStandardNumber(constant)


def _finite_float(text: str) -> float:
    value = float(text)
    if not math.isfinite(value):
        raise _NonStandardNumber(text)
    return value
