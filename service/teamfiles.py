"""A team's files (``team_config.json``, ``credentials.json``): checked like ``hlvs check`` plus
the service's own rules, and kept in versions. Only valid files are stored; an invalid upload
changes nothing stored.

The service's rules (:func:`service_problems`): a team file names only secrets the team gave
the league. Refused: ``registry_auth.password_env`` (an environment variable of the service's
host), ``registry_auth.ecr`` without ``access_id`` and ``access_secret`` (it would sign with
the host's AWS key), a ``private_key`` given as a path and ``known_hosts`` (files of the host);
an SFTP target needs its ``host_key``. No host path or variable is ever looked at, so the
answer tells nothing about the host. Secrets are stored sealed (:mod:`service.sealing`).

:func:`check` is the one check of a team file: the upload, ``.../check`` and the pre-flight
all call it.
"""

from __future__ import annotations

import hashlib
import json
import logging
import urllib.parse
from collections.abc import Mapping
from dataclasses import asdict
from pathlib import Path
from typing import Any

from sqlalchemy import func, select
from sqlalchemy.orm import Session

from orchestrator import ConfigError, Problem
from orchestrator.config import BUILT_IN_MODELS, FieldClass, TeamConfig, check_team_document
from orchestrator.delivery import IPNetwork, literal_problem
from service.db import Submission, TeamFile
from service.errors import InvalidInput, NotFound
from service.sealing import PREFIX, Sealer
from service.settings import LOG_TARGET_ALLOW_SETTING

log = logging.getLogger(__name__)

KINDS = {"team_config": "team_config.json", "credentials": "credentials.json"}


FIELD_CLASS = FieldClass.KID
"""The field class of the service's test matches (``orchestrator.match.scrimmage.game_file``):
the pose rules of the upload are those the pre-flight and the match apply."""
PLACEHOLDER_KEY = ("-----BEGIN OPENSSH PRIVATE KEY-----\n(refused)\n"
                   "-----END OPENSSH PRIVATE KEY-----")


def service_problems(kind: str, document: Any, *, allowed: tuple[IPNetwork, ...] = ()
                     ) -> tuple[Any, list[Problem]]:
    """The service's own rules: ``(document to check further, problems)``. The document
    returned has every refused host reference taken out, so that checking it further reads
    nothing of the host. ``allowed``: the networks a log target may reach besides public
    addresses (``HLVS_SERVICE_LOG_TARGET_ALLOW``)."""
    name = KINDS[kind]
    problems: list[Problem] = []
    if not isinstance(document, dict):
        return document, problems
    if kind == "team_config":
        auth = document.get("registry_auth")
        if isinstance(auth, dict) and "password_env" in auth:
            problems.append(Problem(
                name, "/registry_auth/password_env",
                "password_env is not accepted by the service (it names a variable of the "
                "league's host, not a secret of the team)",
                '"password": the registry password itself (stored encrypted, never shown '
                "back)"))
        ecr = auth.get("ecr") if isinstance(auth, dict) else None
        if isinstance(ecr, dict) and not (ecr.get("access_id") and ecr.get("access_secret")):
            problems.append(Problem(
                name, "/registry_auth/ecr",
                "ECR without access_id and access_secret is not accepted by the service "
                "(it would sign with the league's AWS key)",
                "the team's own access_id and access_secret (stored encrypted)"))
        return _builtin_models_only(document, problems)
    body = document.get("credentials")
    problems += _target_address_problems(document, allowed)
    if document.get("type") != "sftp" or not isinstance(body, dict):
        return document, problems
    cleaned = dict(body)
    key = body.get("private_key")
    if isinstance(key, str) and not key.lstrip().startswith("-----BEGIN"):
        problems.append(Problem(
            name, "/credentials/private_key",
            "a path is not accepted by the service (files of the league's host are not "
            "read for a team)", "the key's text (-----BEGIN ... PRIVATE KEY-----), stored "
            "encrypted"))
        cleaned["private_key"] = PLACEHOLDER_KEY
    if "known_hosts" in body:
        problems.append(Problem(
            name, "/credentials/known_hosts",
            "known_hosts is not accepted by the service (files of the league's host are not "
            "read for a team)", '"host_key": the server\'s key, "ssh-ed25519 AAAA..."'))
        cleaned.pop("known_hosts")
    if body.get("host_key") is None:
        problems.append(Problem(
            name, "/credentials/host_key", "an SFTP target needs its pinned host key in the "
            "service", '"host_key": the server\'s key as in known_hosts, "ssh-ed25519 AAAA..."'))
    return {**document, "credentials": cleaned}, problems


def _target_address_problems(document: Mapping[str, object],
                             allowed: tuple[IPNetwork, ...]) -> list[Problem]:
    """A log target obeys the webhooks' address rules (:mod:`orchestrator.delivery.addresses`):
    an address literal of the league's own networks, or ``localhost``, is refused here; a name
    is resolved and checked again at every delivery, which connects to the address checked."""
    body = document.get("credentials")
    if not isinstance(body, dict):
        return []
    where, host = "", None
    if document.get("type") == "sftp" and isinstance(body.get("hostname"), str):
        where, host = "/credentials/hostname", body["hostname"]
    elif document.get("type") == "s3" and isinstance(body.get("endpoint_url"), str):
        where = "/credentials/endpoint_url"
        try:
            host = urllib.parse.urlsplit(body["endpoint_url"]).hostname or ""
        except ValueError:
            return []  # the schema's check names what is wrong with it
    if host is None:
        return []
    problem = literal_problem(host, allowed, LOG_TARGET_ALLOW_SETTING)
    if problem is None:
        return []
    return [Problem(KINDS["credentials"], where, problem,
                    "a public address or host name (the league's own networks are not a log "
                    "target)")]


def _builtin_models_only(document: Mapping[str, object],
                         problems: list[Problem]) -> tuple[Any, list[Problem]]:
    """A robot model package is a folder of the host that reads the file: refused (and taken
    out, unread) in the service, which plays the built-in models."""
    players = document.get("players")
    if not isinstance(players, dict):
        return document, problems
    kept = dict(players)
    for number, entry in players.items():
        model = entry.get("model") if isinstance(entry, dict) else None
        if isinstance(model, str) and model not in BUILT_IN_MODELS:
            problems.append(Problem(
                KINDS["team_config"], f"/players/{number}/model",
                "a robot model package is not accepted by the service (its folder would be "
                "one of the league's host)", "one of " + ", ".join(BUILT_IN_MODELS)))
            kept[number] = {k: v for k, v in entry.items() if k != "model"}
    return {**document, "players": kept}, problems


def check(kind: str, document: Any, *, allowed: tuple[IPNetwork, ...] = ()
          ) -> list[dict[str, str]]:
    """Every problem of ``document`` as ``hlvs check`` finds it plus the service's rules
    (errors and warnings), with the file named as the team knows it (``team_config.json`` /
    ``credentials.json``). Never raises for a bad document."""
    return _checked(kind, document, allowed=allowed)[1]


def _checked(kind: str, document: Any, *, allowed: tuple[IPNetwork, ...] = ()
             ) -> tuple[TeamConfig | None, list[dict[str, str]]]:
    """The team (for ``team_config`` without an error) and the problems of :func:`check`: the
    document itself is validated, no file is written or read."""
    name = KINDS[kind]
    document, problems = service_problems(kind, document, allowed=allowed)
    team: TeamConfig | None = None
    if kind == "team_config":
        team, found = check_team_document(document, source=name, field_class=FIELD_CLASS,
                                          images_required=True)
        problems += found
        if any(p.severity == "error" for p in problems):
            team = None
    else:
        from orchestrator.config import parse_credentials

        try:
            problems += [w for w in parse_credentials(document, source=Path(name)).warnings
                         if "known_hosts only" not in w.message]
        except ConfigError as exc:
            problems += exc.problems
    out = []
    for problem in problems:
        entry = {k: str(v) for k, v in asdict(problem).items()}
        entry["file"] = name
        entry["text"] = str(problem)
        out.append(entry)
    return team, out


def raise_if_invalid(kind: str, document: Any, *, allowed: tuple[IPNetwork, ...] = ()
                     ) -> list[dict[str, str]]:
    """The problems of ``document`` (warnings); :class:`InvalidInput` when one is an error."""
    return _raise_if_errors(kind, _checked(kind, document, allowed=allowed)[1])


def validated_team(document: Any) -> TeamConfig:
    """The team of a ``team_config`` document, checked once by today's rules (the upload's
    check, the service's rules included); :class:`InvalidInput` with the problems when
    invalid. What a submission's pre-flight and match are built from."""
    team, problems = _checked("team_config", document)
    _raise_if_errors("team_config", problems)
    assert team is not None
    return team


def _raise_if_errors(kind: str, problems: list[dict[str, str]]) -> list[dict[str, str]]:
    errors = [p for p in problems if p["severity"] == "error"]
    if errors:
        raise InvalidInput(f"{KINDS[kind]} has {len(errors)} problem(s): " + errors[0]["text"],
                           problems=problems)
    return problems


def store(session: Session, *, team_id: int, kind: str, document: Any,
          sealer: Sealer, allowed: tuple[IPNetwork, ...] = ()) -> TeamFile:
    """Check and store a new version, its secrets sealed; :class:`InvalidInput` with the
    problems when invalid."""
    if kind not in KINDS:
        raise NotFound(what="file kind", ident=kind)
    problems = raise_if_invalid(kind, document, allowed=allowed)
    content = json.dumps(sealer.seal_document(kind, document), indent=2, sort_keys=False)
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


def current(session: Session, *, team_id: int, kind: str = "team_config") -> TeamFile | None:
    """The version another team's friendly or the ladder plays: the newest valid one whose
    pre-flight passed (a submission was made with it after its check), so a newer upload not
    checked yet (or one that fails its check) never displaces it; while no version has passed
    one, the newest valid one."""
    valid = select(TeamFile).where(TeamFile.team_id == team_id, TeamFile.kind == kind,
                                   TeamFile.valid.is_(True)).order_by(TeamFile.version.desc())
    passed = session.scalar(valid.where(select(Submission.id).where(
        Submission.team_file_id == TeamFile.id, Submission.preflight_s.is_not(None))
        .exists()).limit(1))
    return passed if passed is not None else session.scalar(valid.limit(1))


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





def opened(row: TeamFile, sealer: Sealer) -> Any:
    """The stored document with its secrets opened (for a match, a pre-flight, a delivery)."""
    return sealer.open_document(row.kind, json.loads(row.content))


def seal_stored(session: Session, sealer: Sealer) -> int:
    """Seal every secret still stored in the clear (stored before sealing existed); returns
    how many rows changed. :class:`~service.errors.SettingsError` when a sealed secret does
    not open with ``sealer`` (the service was started with another key)."""
    from service.db import Team

    changed = 0
    opened_one = False
    for row in session.scalars(select(TeamFile)):
        document = json.loads(row.content)
        if not opened_one and PREFIX in row.content:
            sealer.open_document(row.kind, document)  # raises with the wrong key
            opened_one = True
        sealed = sealer.seal_document(row.kind, document)
        if sealed != document:
            row.content = json.dumps(sealed, indent=2, sort_keys=False)
            changed += 1
    for team in session.scalars(select(Team).where(Team.webhook_secret.is_not(None))):
        if team.webhook_secret and not team.webhook_secret.startswith(PREFIX):
            team.webhook_secret = sealer.seal(team.webhook_secret)
            changed += 1
    if changed:
        log.info("%d stored secret(s) sealed", changed)
    return changed


def get_by_id(session: Session, file_id: int) -> TeamFile:
    row = session.get(TeamFile, file_id)
    if row is None:
        raise NotFound(what="uploaded file", ident=str(file_id))
    return row


def newest_id(session: Session, *, team_id: int, kind: str) -> int | None:
    return session.scalar(select(TeamFile.id).where(
        TeamFile.team_id == team_id, TeamFile.kind == kind)
        .order_by(TeamFile.version.desc()).limit(1))


__all__ = ["KINDS", "check", "current", "get", "get_by_id", "newest_id", "opened",
           "raise_if_invalid", "refuse", "seal_stored", "service_problems", "store",
           "validated_team", "versions"]
