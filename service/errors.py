"""Errors of the service package. Every error carries data and builds its own message.

Tree::

    ServiceError
    ├── SettingsError        a setting (environment variable) has a value that cannot be used
    ├── AuthError            a request has no usable token (HTTP 401); ``reason`` says which
    ├── NotFound             no such object for this caller (HTTP 404; other teams' ids too)
    ├── Conflict             the request clashes with stored state (HTTP 409), e.g. one active
    │                        submission per team; ``existing_id`` names the one in the way
    ├── InvalidInput         a body or file is unusable (HTTP 422); carries its problems
    ├── PreflightFailed      a team's images failed the pre-flight check (HTTP 422)
    └── ClientError          the command-line client got an error answer or no answer

The HTTP layer turns each into one JSON body ``{"error": kind, "message": ..., ...fields}``
in exactly one place (:mod:`service.app`), which also answers the cluster's
``cluster.PoolError`` (the match pool could not start, query or stop a match) with HTTP 503.
"""

from __future__ import annotations

from typing import TypeAlias

# The fields an error adds to its JSON body: text, or an invalid input's problems (each with
# its file, pointer, message...)
ErrorFields: TypeAlias = dict[str, str | list[dict[str, str]]]


class ServiceError(Exception):
    """Root of every error the service package raises."""

    status_code = 500
    kind = "internal"
    exit_code = 1

    def fields(self) -> ErrorFields:
        return {}


class SettingsError(ServiceError):
    exit_code = 2
    kind = "settings"

    def __init__(self, *, name: str, value: str, expected: str) -> None:
        self.name = name
        self.value = value
        self.expected = expected
        super().__init__(f"setting {name}={value!r}: expected {expected}")


class AuthError(ServiceError):
    status_code = 401
    kind = "unauthorized"

    def __init__(self, reason: str, message: str) -> None:
        self.reason = reason  # missing, malformed, unknown, expired, revoked, scope
        super().__init__(message)

    def fields(self) -> ErrorFields:
        return {"reason": self.reason}


class NotFound(ServiceError):
    status_code = 404
    kind = "not_found"
    exit_code = 2

    def __init__(self, *, what: str, ident: str) -> None:
        self.what = what
        self.ident = ident
        super().__init__(f"no {what} {ident!r}")

    def fields(self) -> ErrorFields:
        return {"what": self.what, "id": self.ident}


class Conflict(ServiceError):
    status_code = 409
    kind = "conflict"
    exit_code = 2

    def __init__(self, message: str, *, existing_id: str | None = None) -> None:
        self.existing_id = existing_id
        super().__init__(message)

    def fields(self) -> ErrorFields:
        return {"existing_id": self.existing_id} if self.existing_id else {}


class InvalidInput(ServiceError):
    status_code = 422
    kind = "invalid_input"
    exit_code = 2

    def __init__(self, message: str, *, problems: list[dict[str, str]] | None = None) -> None:
        self.problems = list(problems or [])
        super().__init__(message)

    def fields(self) -> ErrorFields:
        return {"problems": self.problems} if self.problems else {}


class PreflightFailed(ServiceError):
    status_code = 422
    kind = "preflight_failed"

    def __init__(self, *, stage: str, image: str, cause: str) -> None:
        self.stage = stage  # pull, size, start, connect, config
        self.image = image
        self.cause = cause
        super().__init__(f"pre-flight check failed at {stage} for image {image}: {cause}")

    def fields(self) -> ErrorFields:
        return {"stage": self.stage, "image": self.image, "cause": self.cause}


class ClientError(ServiceError):
    def __init__(self, *, url: str, status: int | None, message: str) -> None:
        self.url = url
        self.status = status
        exit_code = 3 if status is None else 2 if status in (400, 401, 404, 409, 413, 415, 422) \
            else 1
        self.exit_code = exit_code
        where = f"{url}: HTTP {status}" if status is not None else f"{url}: no answer"
        super().__init__(f"{where}: {message}")
