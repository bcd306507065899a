"""Reading raw request bodies: content type, size limit, JSON syntax, with precise errors."""

from __future__ import annotations

import json
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
        return json.loads(raw.decode("utf-8"))
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


__all__ = ["read_json_body"]
