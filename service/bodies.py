"""Reading raw request bodies: content type, size limit, JSON syntax, with precise errors."""

from __future__ import annotations

import json
import math
from typing import Any

from fastapi import Request
from starlette.exceptions import HTTPException

from service.errors import InvalidInput


async def read_json_body(request: Request, *, limit_bytes: int, name: str) -> Any:
    """The JSON document in the body of ``request``; 415 for a wrong content type, 413 past
    ``limit_bytes`` (checked while reading, whatever Content-Length says), 422 for bad JSON."""
    content_type = request.headers.get("content-type", "").split(";")[0].strip().lower()
    if content_type != "application/json":
        raise HTTPException(415, f"{name}: content type {content_type or '(none)'!r} is not "
                                 "accepted (expected application/json)")
    declared = request.headers.get("content-length")
    if declared is not None and declared.isdigit() and int(declared) > limit_bytes:
        raise HTTPException(413, f"{name}: {declared} bytes is over the limit of "
                                 f"{limit_bytes} bytes")
    chunks: list[bytes] = []
    size = 0
    async for chunk in request.stream():
        size += len(chunk)
        if size > limit_bytes:
            raise HTTPException(413, f"{name}: the body is over the limit of {limit_bytes} bytes")
        chunks.append(chunk)
    raw = b"".join(chunks)
    try:
        document = json.loads(raw.decode("utf-8"), parse_float=_finite, parse_int=_integer,
                              parse_constant=_no_constant)
    except UnicodeDecodeError as exc:
        raise InvalidInput(f"{name}: not UTF-8 text (byte {exc.start})", problems=[
            {"file": name, "pointer": "", "message": "not UTF-8 text", "expected": "UTF-8"}
        ]) from None
    except json.JSONDecodeError as exc:
        raise InvalidInput(
            f"{name}: invalid JSON at line {exc.lineno} column {exc.colno}: {exc.msg}",
            problems=[{"file": name, "pointer": "", "expected": "a JSON document",
                       "message": f"invalid JSON at line {exc.lineno} column {exc.colno}: "
                                  f"{exc.msg}"}],
        ) from None
    except RecursionError:
        raise _unreadable(name, deep_pointer(raw, MAX_DEPTH) or "",
                          f"nested deeper than {MAX_DEPTH} levels",
                          f"at most {MAX_DEPTH} levels of nesting") from None
    except _BadNumber as exc:
        raise _unreadable(name, "", str(exc), "a finite number of at most "
                          f"{MAX_DIGITS} digits") from None
    deep = _too_deep(document)
    if deep is not None:
        raise _unreadable(name, deep, f"nested deeper than {MAX_DEPTH} levels",
                          f"at most {MAX_DEPTH} levels of nesting")
    lone = surrogate_pointer(document)
    if lone is not None:
        raise _unreadable(name, lone, "a lone surrogate (\\ud800-\\udfff) is not text",
                          "text that is valid Unicode (a character, not half of a UTF-16 "
                          "pair)")
    return document


MAX_DEPTH = 64
"""Nesting a JSON body may have (a team file needs 5)."""
MAX_DIGITS = 400


class _BadNumber(ValueError):
    pass


def _finite(text: str) -> float:
    value = float(text)
    if len(text) > MAX_DIGITS or not math.isfinite(value):
        raise _BadNumber(f"the number {text[:20]}{'...' if len(text) > 20 else ''} is out of "
                         "range")
    return value


def _integer(text: str) -> int:
    if len(text) > MAX_DIGITS:
        raise _BadNumber(f"the number {text[:20]}... has {len(text)} digits")
    return int(text)


def _no_constant(text: str) -> float:
    raise _BadNumber(f"{text} is not a JSON number")


def _too_deep(document: Any) -> str | None:
    """The JSON pointer of a value nested deeper than :data:`MAX_DEPTH`, None when none is
    (walked without recursion)."""
    stack: list[tuple[Any, str, int]] = [(document, "", 0)]
    while stack:
        value, at, depth = stack.pop()
        if depth > MAX_DEPTH:
            return at
        if isinstance(value, dict):
            stack.extend((v, f"{at}/{_escape(str(k))}", depth + 1) for k, v in value.items())
        elif isinstance(value, list):
            stack.extend((v, f"{at}/{i}", depth + 1) for i, v in enumerate(value))
    return None


def deep_pointer(raw: bytes, limit: int = MAX_DEPTH) -> str | None:
    """The JSON pointer of the first array or object nested deeper than ``limit`` in the JSON
    text ``raw``, found by scanning its structure (a document too deep for the parser has one
    all the same); None when there is none."""
    # each open container: [is an object, current index or key, a key is expected next]
    stack: list[list[Any]] = []
    i, n = 0, len(raw)
    while i < n:
        c = raw[i]
        if c == 0x22:  # a string: a key when an object expects one
            j = i + 1
            while j < n and raw[j] != 0x22:
                j += 2 if raw[j] == 0x5C else 1
            if stack and stack[-1][0] and stack[-1][2]:
                try:
                    stack[-1][1] = json.loads(raw[i:j + 1])
                except ValueError:
                    stack[-1][1] = raw[i + 1:j].decode("utf-8", "replace")
                stack[-1][2] = False
            i = j + 1
            continue
        if c in (0x5B, 0x7B):  # [ {
            if len(stack) > limit:
                return "".join(f"/{_escape(str(entry[1]))}" for entry in stack)
            stack.append([c == 0x7B, None if c == 0x7B else 0, c == 0x7B])
        elif c in (0x5D, 0x7D) and stack:  # ] }
            stack.pop()
        elif c == 0x2C and stack:  # ,
            if stack[-1][0]:
                stack[-1][2] = True
            else:
                stack[-1][1] += 1
        i += 1
    return None


def surrogate_pointer(document: Any) -> str | None:
    """The JSON pointer of a key or string holding a lone surrogate (``"\\udc80"`` is valid
    JSON but no text: it cannot be stored, sealed or sent), None when none does."""
    stack: list[tuple[Any, str]] = [(document, "")]
    while stack:
        value, at = stack.pop()
        if isinstance(value, str):
            if _has_surrogate(value):
                return _printable(at)
        elif isinstance(value, dict):
            for k, v in value.items():
                where = f"{at}/{_escape(str(k))}"
                if _has_surrogate(str(k)):
                    return _printable(where)
                stack.append((v, where))
        elif isinstance(value, list):
            stack.extend((v, f"{at}/{i}") for i, v in enumerate(value))
    return None


def _has_surrogate(text: str) -> bool:
    try:
        text.encode("utf-8")
    except UnicodeEncodeError:
        return True
    return False


def _printable(pointer: str) -> str:
    """A pointer that can be sent back: its lone surrogates as ``\\udXXX``."""
    return pointer.encode("utf-8", "backslashreplace").decode("utf-8")


def _escape(key: str) -> str:
    return key.replace("~", "~0").replace("/", "~1")


def _unreadable(name: str, pointer: str, message: str, expected: str) -> InvalidInput:
    return InvalidInput(f"{name}: {pointer or '/'}: {message}", problems=[
        {"file": name, "pointer": pointer, "message": message, "expected": expected}])


__all__ = ["MAX_DEPTH", "deep_pointer", "read_json_body", "surrogate_pointer"]
