"""API tokens: issue, revoke, verify. Domain code, no HTTP.

A token reads ``hlvs_<id>_<secret>``. The id is the table's key and may be shown (``hlvs admin
token list``); only the SHA-256 of the secret is stored, so a leaked database holds no usable
token. Tokens are never logged: log lines name the token id only.
"""

from __future__ import annotations

import hashlib
import hmac
import logging
import re
import secrets
from dataclasses import dataclass
from datetime import datetime, timedelta

from sqlalchemy import select
from sqlalchemy.orm import Session

from service.db import Scope, Team, Token, now, utc
from service.errors import AuthError, NotFound

log = logging.getLogger(__name__)

TOKEN_RE = re.compile(r"^hlvs_([a-z0-9]{12})_([A-Za-z0-9_-]{32,64})$")


@dataclass(frozen=True, slots=True)
class Principal:
    """Who a request speaks for: a team (``team_id`` set) or an operator."""

    token_id: str
    scope: Scope
    team_id: int | None
    team_name: str | None


@dataclass(frozen=True, slots=True)
class IssuedToken:
    token_id: str
    secret: str  # the whole ``hlvs_<id>_<secret>`` string; shown once, never stored
    scope: Scope
    team: str | None
    expires_at: datetime | None


def _digest(secret: str) -> str:
    return hashlib.sha256(secret.encode()).hexdigest()


def issue(session: Session, *, scope: Scope, team: str | None, days: float | None,
          label: str = "") -> IssuedToken:
    """A new token; ``days`` None means no expiry. Team tokens need an existing team."""
    team_id = None
    if scope is Scope.TEAM:
        if team is None:
            raise NotFound(what="team", ident="(none given)")
        row = session.scalar(select(Team).where(Team.name == team))
        if row is None:
            raise NotFound(what="team", ident=team)
        team_id = row.id
    token_id = secrets.token_hex(6)
    secret = secrets.token_urlsafe(32)
    expires = None if days is None else now() + timedelta(days=days)
    session.add(Token(id=token_id, team_id=team_id, scope=scope.value,
                      secret_sha256=_digest(secret), label=label, expires_at=expires))
    log.info("token %s issued (scope %s, team %s)", token_id, scope.value, team or "-")
    return IssuedToken(token_id=token_id, secret=f"hlvs_{token_id}_{secret}", scope=scope,
                       team=team, expires_at=expires)


def revoke(session: Session, token_id: str) -> Token:
    token = session.get(Token, token_id)
    if token is None:
        raise NotFound(what="token", ident=token_id)
    if token.revoked_at is None:
        token.revoked_at = now()
        log.info("token %s revoked", token_id)
    return token


def verify(session: Session, presented: str | None) -> Principal:
    """The principal of ``presented``; :class:`AuthError` says why not (never echoes it)."""
    if not presented:
        raise AuthError("missing", "no token: send the header 'Authorization: Bearer <token>'")
    match = TOKEN_RE.match(presented)
    if match is None:
        raise AuthError("malformed", "the token is malformed (expected hlvs_<id>_<secret>)")
    token_id, secret = match.groups()
    token = session.get(Token, token_id)
    if token is None or not hmac.compare_digest(token.secret_sha256, _digest(secret)):
        raise AuthError("unknown", "the token is not known to this service")
    if token.revoked_at is not None:
        raise AuthError("revoked", f"the token {token_id} was revoked at "
                        f"{utc(token.revoked_at).isoformat(timespec='seconds')}")
    if token.expires_at is not None and utc(token.expires_at) <= now():
        raise AuthError("expired", f"the token {token_id} expired at "
                        f"{utc(token.expires_at).isoformat(timespec='seconds')}")
    team_name = None
    if token.team_id is not None:
        team = session.get(Team, token.team_id)
        team_name = team.name if team else None
    return Principal(token_id=token_id, scope=Scope(token.scope), team_id=token.team_id,
                     team_name=team_name)


__all__ = ["IssuedToken", "Principal", "TOKEN_RE", "issue", "revoke", "verify"]
