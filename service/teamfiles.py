"""A team's files (``team_config.json``, ``credentials.json``): checked like ``hlvs check`` and
kept in versions. Only valid files are stored; an invalid upload changes nothing stored."""

from __future__ import annotations

import hashlib
import json
import logging
import tempfile
from dataclasses import asdict
from pathlib import Path
from typing import Any

from sqlalchemy import func, select
from sqlalchemy.orm import Session

from orchestrator.config import check_team
from orchestrator.errors import ConfigError, Problem
from service.db import TeamFile
from service.errors import InvalidInput, NotFound

log = logging.getLogger(__name__)

KINDS = {"team_config": "team_config.json", "credentials": "credentials.json"}


def check(kind: str, document: Any) -> list[dict[str, str]]:
    """Every problem of ``document`` as ``hlvs check`` finds it (errors and warnings), with the
    file named as the team knows it (``team_config.json`` / ``credentials.json``)."""
    name = KINDS[kind]
    with tempfile.TemporaryDirectory(prefix="hlvs-check-") as folder:
        path = Path(folder) / name
        path.write_text(json.dumps(document), encoding="utf-8")
        path.chmod(0o600)
        problems: list[Problem]
        if kind == "team_config":
            problems = check_team(path, images_required=True)
        else:
            from orchestrator.config.credentials import load_credentials

            try:
                problems = list(load_credentials(path).warnings)
            except ConfigError as exc:
                problems = exc.problems
    out = []
    for problem in problems:
        entry = {k: str(v) for k, v in asdict(problem).items()}
        entry["file"] = name
        entry["text"] = str(problem).replace(str(path), name)
        out.append(entry)
    return out


def store(session: Session, *, team_id: int, kind: str, document: Any) -> TeamFile:
    """Check and store a new version; :class:`InvalidInput` with the problems when invalid."""
    if kind not in KINDS:
        raise NotFound(what="file kind", ident=kind)
    problems = check(kind, document)
    errors = [p for p in problems if p["severity"] == "error"]
    if errors:
        raise InvalidInput(f"{KINDS[kind]} has {len(errors)} problem(s): " + errors[0]["text"],
                           problems=problems)
    content = json.dumps(document, indent=2, sort_keys=False)
    latest = session.scalar(select(func.max(TeamFile.version)).where(
        TeamFile.team_id == team_id, TeamFile.kind == kind)) or 0
    row = TeamFile(team_id=team_id, kind=kind, version=latest + 1, content=content,
                   sha256=hashlib.sha256(content.encode()).hexdigest(), valid=True,
                   problems_json=json.dumps(problems))
    session.add(row)
    session.flush()
    log.info("team %d: %s version %d stored", team_id, KINDS[kind], row.version)
    return row


def get(session: Session, *, team_id: int, kind: str, version: int | None = None) -> TeamFile:
    """The given version, or the current one: the newest that did not fail a pre-flight
    check (:func:`refuse`)."""
    if kind not in KINDS:
        raise NotFound(what="file kind", ident=kind)
    query = select(TeamFile).where(TeamFile.team_id == team_id, TeamFile.kind == kind)
    if version is not None:
        query = query.where(TeamFile.version == version)
    else:
        query = query.where(TeamFile.valid.is_(True))
    row = session.scalar(query.order_by(TeamFile.version.desc()).limit(1))
    if row is None:
        ident = KINDS[kind] + (f" version {version}" if version is not None else "")
        what = "uploaded file" if version is not None else "uploaded file that passed its checks"
        raise NotFound(what=what, ident=ident)
    return row


def refuse(session: Session, row: TeamFile, *, stage: str, cause: str) -> None:
    """A version that failed the pre-flight check never becomes current: marked invalid, with
    the failure among its problems (the previous valid version stays current)."""
    problems = json.loads(row.problems_json)
    text = f"pre-flight check failed at {stage}: {cause}"
    problems.append({"file": KINDS[row.kind], "pointer": "", "message": text, "expected": "",
                     "suggestion": "", "severity": "error", "text": text})
    row.valid = False
    row.problems_json = json.dumps(problems)
    log.info("team %d: %s version %d failed its pre-flight check: not current", row.team_id,
             KINDS[row.kind], row.version)


def versions(session: Session, *, team_id: int, kind: str) -> list[TeamFile]:
    return list(session.scalars(select(TeamFile).where(
        TeamFile.team_id == team_id, TeamFile.kind == kind).order_by(TeamFile.version)))





def get_by_id(session: Session, file_id: int) -> TeamFile:
    row = session.get(TeamFile, file_id)
    if row is None:
        raise NotFound(what="uploaded file", ident=str(file_id))
    return row


def newest_id(session: Session, *, team_id: int, kind: str) -> int | None:
    return session.scalar(select(TeamFile.id).where(
        TeamFile.team_id == team_id, TeamFile.kind == kind)
        .order_by(TeamFile.version.desc()).limit(1))


__all__ = ["KINDS", "check", "get", "get_by_id", "newest_id", "refuse", "store", "versions"]
