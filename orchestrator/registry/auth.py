"""Authentication with a registry as the distribution specification describes it.

A registry answers 401 with a ``WWW-Authenticate`` challenge. ``Basic realm=...`` asks for the
user and password on every request. ``Bearer realm=...,service=...,scope=...`` sends the client to
a token service: ``GET realm?service=...&scope=...`` with the user and password (or none, for
anonymous pulls) returns a token that is sent as ``Authorization: Bearer`` until it expires
(``expires_in``, at least 60 s by the specification). Tokens are cached per scope and fetched
again shortly before they expire or when the registry refuses one.
"""

from __future__ import annotations

import base64
import re
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field

DEFAULT_EXPIRES_S = 60.0  # when the token service names no lifetime (the specification's default)
REFRESH_MARGIN_S = 5.0  # fetch a new token this long before the old one expires (at most 10 %)

_TOKEN = re.compile(r'([A-Za-z0-9_.-]+)(?:\s*=\s*("(?:[^"\\]|\\.)*"|[^\s,]*))?')


@dataclass(frozen=True, slots=True, kw_only=True)
class Credentials:
    """A registry user and password (a team's login, or ``AWS`` and an ECR token)."""

    username: str
    password: str = field(repr=False)

    def basic(self) -> str:
        pair = f"{self.username}:{self.password}".encode()
        return "Basic " + base64.b64encode(pair).decode()


@dataclass(frozen=True, slots=True)
class Challenge:
    """One ``WWW-Authenticate`` challenge: the scheme (lower case) and its parameters."""

    scheme: str
    params: Mapping[str, str]

    @property
    def realm(self) -> str:
        return self.params.get("realm", "")


def parse_challenges(header: str) -> list[Challenge]:
    """The challenges of a ``WWW-Authenticate`` header (quoted values may hold commas)."""
    challenges: list[Challenge] = []
    for token in _TOKEN.finditer(header):
        name, value = token.group(1), token.group(2)
        if value is None:
            challenges.append(Challenge(name.lower(), {}))
        elif challenges:
            if value.startswith('"'):
                value = re.sub(r"\\(.)", r"\1", value[1:-1])
            params = dict(challenges[-1].params)
            params[name.lower()] = value
            challenges[-1] = Challenge(challenges[-1].scheme, params)
    return challenges


def scope_for(method: str, path: str) -> str:
    """The scope a request needs, as the registry would ask for it (used when the challenge
    names none): ``repository:NAME:pull`` for reads, ``...:delete`` for deletions,
    ``registry:catalog:*`` for the catalog."""
    if path.startswith("/v2/_catalog"):
        return "registry:catalog:*"
    found = re.match(r"/v2/(.+?)/(?:manifests|blobs|tags)/", path)
    if not found:
        return ""
    action = {"DELETE": "delete", "GET": "pull", "HEAD": "pull"}.get(method, "pull,push")
    return f"repository:{found.group(1)}:{action}"


@dataclass(slots=True)
class _Token:
    value: str
    expires_at: float


@dataclass(slots=True)
class TokenCache:
    """Bearer tokens by (realm, service, scope), valid until shortly before they expire."""

    clock: Callable[[], float]
    _tokens: dict[tuple[str, str, str], _Token] = field(default_factory=dict)

    def get(self, key: tuple[str, str, str]) -> str | None:
        token = self._tokens.get(key)
        if token is None or self.clock() >= token.expires_at:
            return None
        return token.value

    def put(self, key: tuple[str, str, str], value: str, *, expires_in_s: float | None) -> None:
        lifetime = DEFAULT_EXPIRES_S if expires_in_s is None else max(float(expires_in_s), 0.0)
        margin = min(REFRESH_MARGIN_S, lifetime / 10)
        self._tokens[key] = _Token(value, self.clock() + lifetime - margin)

    def drop(self, key: tuple[str, str, str]) -> None:
        self._tokens.pop(key, None)


__all__ = ["Challenge", "Credentials", "TokenCache", "parse_challenges", "scope_for"]
