"""Accounts and tokens for operators, used by ``hlvs admin`` (domain code, no HTTP)."""

from __future__ import annotations

import logging
import re

from sqlalchemy import select
from sqlalchemy.orm import Session

from service.db import Team, Token, utc
from service.errors import Conflict, InvalidInput

log = logging.getLogger(__name__)

TEAM_NAME_RE = re.compile(r"^[A-Za-z0-9][A-Za-z0-9 ._-]{0,63}$")


def add_team(session: Session, *, name: str, email: str | None = None,
             accepts_friendlies: bool = False) -> Team:
    if not TEAM_NAME_RE.match(name) or name == "stub":
        raise InvalidInput(f"team name {name!r} is not allowed (expected 1-64 letters, digits, "
                           "spaces, '.', '_' or '-', starting with a letter or digit; not "
                           "'stub')")
    if session.scalar(select(Team).where(Team.name == name)) is not None:
        raise Conflict(f"a team named {name!r} exists already")
    team = Team(name=name, email=email, accepts_friendlies=accepts_friendlies)
    session.add(team)
    session.flush()
    log.info("team %s added (id %d)", name, team.id)
    return team


def list_tokens(session: Session) -> list[dict[str, object]]:
    rows = session.execute(select(Token, Team.name).outerjoin(Team, Token.team_id == Team.id)
                           .order_by(Token.created_at)).all()
    return [{
        "id": token.id, "scope": token.scope, "team": team_name, "label": token.label,
        "created_at": utc(token.created_at).isoformat(timespec="seconds"),
        "expires_at": utc(token.expires_at).isoformat(timespec="seconds")
        if token.expires_at else None,
        "revoked_at": utc(token.revoked_at).isoformat(timespec="seconds")
        if token.revoked_at else None,
    } for token, team_name in rows]


__all__ = ["add_team", "list_tokens"]
