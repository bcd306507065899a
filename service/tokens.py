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
import threading
import time
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
    expires_at: datetime | None = None


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
    row = session.execute(
        select(Token.secret_sha256, Token.scope, Token.team_id, Token.revoked_at,
               Token.expires_at, Team.name)
        .outerjoin(Team, Team.id == Token.team_id).where(Token.id == token_id)).first()
    if row is None or not hmac.compare_digest(row.secret_sha256, _digest(secret)):
        raise AuthError("unknown", "the token is not known to this service")
    if row.revoked_at is not None:
        raise AuthError("revoked", f"the token {token_id} was revoked at "
                        f"{utc(row.revoked_at).isoformat(timespec='seconds')}")
    if row.expires_at is not None and utc(row.expires_at) <= now():
        raise AuthError("expired", f"the token {token_id} expired at "
                        f"{utc(row.expires_at).isoformat(timespec='seconds')}")
    return Principal(token_id=token_id, scope=Scope(row.scope), team_id=row.team_id,
                     team_name=row.name,
                     expires_at=utc(row.expires_at) if row.expires_at else None)


class TokenCache:
    """Tokens verified in the last ``ttl_s`` seconds (keyed by their SHA-256), so that a client
    polling every second costs no token query. A revoked token is refused at the latest
    ``ttl_s`` after the revocation; expiry is checked on every use. :meth:`revalidate` checks
    every cached token again in one query (the status board's thread calls it on each
    rebuild), so that a client that keeps polling keeps its entry."""

    def __init__(self, *, ttl_s: float = 2.0, max_entries: int = 10_000) -> None:
        self.ttl_s = ttl_s
        self.max_entries = max_entries
        self._entries: dict[str, tuple[Principal, float]] = {}
        self._lock = threading.Lock()

    def cached(self, presented: str | None) -> Principal | None:
        """The principal of a token verified less than ``ttl_s`` ago and not expired since."""
        if not presented:
            return None
        key = _digest(presented)
        with self._lock:
            hit = self._entries.get(key)
        if hit is not None and time.monotonic() - hit[1] < self.ttl_s:
            principal = hit[0]
            if principal.expires_at is None or principal.expires_at > now():
                return principal
        return None

    def revalidate(self, session: Session) -> None:
        """Renew the entries of tokens that are still neither revoked nor expired (one query);
        drop the others."""
        if self.ttl_s <= 0:
            return
        with self._lock:
            entries = dict(self._entries)
        if not entries:
            return
        ids = {principal.token_id for principal, _ in entries.values()}
        rows = session.execute(select(Token.id, Token.revoked_at, Token.expires_at).where(
            Token.id.in_(ids))).all()
        current = now()
        valid = {row.id for row in rows if row.revoked_at is None and (
            row.expires_at is None or utc(row.expires_at) > current)}
        renewed = time.monotonic()
        with self._lock:
            for key, (principal, _) in entries.items():
                if principal.token_id in valid:
                    if key in self._entries:
                        self._entries[key] = (principal, renewed)
                else:
                    self._entries.pop(key, None)

    def verify(self, session: Session, presented: str | None) -> Principal:
        principal = self.cached(presented)
        if principal is not None:
            return principal
        principal = verify(session, presented)
        key = _digest(presented or "")
        with self._lock:
            if len(self._entries) >= self.max_entries:
                self._entries.clear()
            self._entries[key] = (principal, time.monotonic())
        return principal


__all__ = ["IssuedToken", "Principal", "TOKEN_RE", "TokenCache", "issue", "revoke", "verify"]
