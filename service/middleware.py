"""ASGI middlewares of the service (plain ASGI: no task or stream per request).

- :class:`BodyLimit`: a body larger than ``max_upload_bytes`` is refused (413): at once when
  its Content-Length says so, else as soon as the bytes read so far pass the limit (a chunked
  body has no Content-Length), before any route, token check or body parser holds more.
- :class:`StatusFastPath`: ``GET /v1/submissions/<id>`` answered from the status board
  (:mod:`service.statusboard`) when the caller's token is in the token cache and the board
  holds that team's submission; anything else goes on to the routes, which answer the same
  JSON from the database.
"""

from __future__ import annotations

import json
import re
from typing import TYPE_CHECKING

from starlette.exceptions import HTTPException
from starlette.types import ASGIApp, Message, Receive, Scope, Send

from service.db import Scope as TokenScope

if TYPE_CHECKING:
    from service.services import Services

BODY_KEY = "hlvs.body"
"""The chunks of a request's body as read (in its scope): a body the route's parser could not
read (JSON nested too deep for it) is looked at again for the error's pointer."""
STATUS_PATH = re.compile(r"^/v1/submissions/([A-Za-z0-9_]{1,32})$")


class BodyTooLarge(HTTPException):
    """Raised by the counting ``receive`` of :class:`BodyLimit` (answered 413)."""

    def __init__(self, limit: int) -> None:
        super().__init__(413, f"the body is over the limit of {limit} bytes")


class BodyLimit:
    def __init__(self, app: ASGIApp, *, max_bytes: int) -> None:
        self.app = app
        self.max_bytes = max_bytes

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        if scope["type"] != "http":
            await self.app(scope, receive, send)
            return
        has_body = False
        for name, value in scope["headers"]:
            if name == b"content-length":
                declared = value.decode("latin-1")
                if declared.isdigit() and int(declared) > self.max_bytes:
                    await _send_json(send, 413, {"error": "too_large", "message": (
                        f"the body of {declared} bytes is over the limit of "
                        f"{self.max_bytes} bytes")})
                    return
                has_body = True
            elif name == b"transfer-encoding":
                has_body = True
        if not has_body:  # HTTP/1.1: neither header, no body (a status poll)
            await self.app(scope, receive, send)
            return
        received = 0
        started = False
        kept: list[bytes] = scope.setdefault(BODY_KEY, [])

        async def counted() -> Message:
            nonlocal received
            message = await receive()
            if message["type"] == "http.request":
                kept.append(message.get("body", b""))
                received += len(message.get("body", b""))
                if received > self.max_bytes:
                    raise BodyTooLarge(self.max_bytes)
            return message

        async def tracked(message: Message) -> None:
            nonlocal started
            if message["type"] == "http.response.start":
                started = True
            await send(message)

        try:
            await self.app(scope, counted, tracked)
        except BodyTooLarge as exc:  # read outside a route (the routes answer it themselves)
            if started:
                raise
            await _send_json(send, 413, {"error": "too_large", "message": str(exc.detail)})


class StatusFastPath:
    def __init__(self, app: ASGIApp) -> None:
        self.app = app

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        if scope["type"] == "http" and scope["method"] == "GET":
            found = STATUS_PATH.match(scope["path"])
            if found is not None:
                body = self._from_board(scope, found.group(1))
                if body is not None:
                    await send({"type": "http.response.start", "status": 200, "headers": [
                        (b"content-type", b"application/json"),
                        (b"content-length", str(len(body)).encode())]})
                    await send({"type": "http.response.body", "body": body})
                    return
        await self.app(scope, receive, send)

    @staticmethod
    def _from_board(scope: Scope, submission_id: str) -> bytes | None:
        app = scope.get("app")
        services: Services | None = getattr(getattr(app, "state", None), "services", None)
        if services is None or services.tokens is None or services.status is None:
            return None
        token = None
        for name, value in scope["headers"]:
            if name == b"authorization":
                scheme, _, token = value.decode("latin-1").partition(" ")
                if scheme.lower() != "bearer":
                    return None
                break
        principal = services.tokens.cached(token)
        if principal is None or principal.scope is not TokenScope.TEAM:
            return None
        body: bytes | None = services.status.lookup(submission_id, principal.team_id)
        return body


async def _send_json(send: Send, status: int, content: dict[str, str]) -> None:
    """An error answer (``{"error": kind, "message": text}``) sent before any handler ran."""
    body = json.dumps(content).encode()
    await send({"type": "http.response.start", "status": status, "headers": [
        (b"content-type", b"application/json"), (b"content-length", str(len(body)).encode())]})
    await send({"type": "http.response.body", "body": body})


__all__ = ["BODY_KEY", "BodyLimit", "BodyTooLarge", "STATUS_PATH", "StatusFastPath"]
