"""ASGI middlewares of the service (plain ASGI: no task or stream per request).

- :class:`BodyLimit`: a body declared larger than ``max_upload_bytes`` is refused (413) before
  it is read.
- :class:`StatusFastPath`: ``GET /v1/submissions/<id>`` answered from the status board
  (:mod:`service.statusboard`) when the caller's token is in the token cache and the board
  holds that team's submission; anything else goes on to the routes, which answer the same
  JSON from the database.
"""

from __future__ import annotations

import json
import re
from typing import TYPE_CHECKING, Any

from starlette.types import ASGIApp, Receive, Scope, Send

from service.db import Scope as TokenScope

if TYPE_CHECKING:
    from service.app import Services

STATUS_PATH = re.compile(r"^/v1/submissions/([A-Za-z0-9_]{1,32})$")


class BodyLimit:
    def __init__(self, app: ASGIApp, *, max_bytes: int) -> None:
        self.app = app
        self.max_bytes = max_bytes

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        if scope["type"] == "http":
            for name, value in scope["headers"]:
                if name == b"content-length":
                    declared = value.decode("latin-1")
                    if declared.isdigit() and int(declared) > self.max_bytes:
                        await _send_json(send, 413, {"error": "too_large", "message": (
                            f"the body of {declared} bytes is over the limit of "
                            f"{self.max_bytes} bytes")})
                        return
                    break
        await self.app(scope, receive, send)


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


async def _send_json(send: Send, status: int, content: dict[str, Any]) -> None:
    body = json.dumps(content).encode()
    await send({"type": "http.response.start", "status": status, "headers": [
        (b"content-type", b"application/json"), (b"content-length", str(len(body)).encode())]})
    await send({"type": "http.response.body", "body": body})


__all__ = ["BodyLimit", "STATUS_PATH", "StatusFastPath"]
