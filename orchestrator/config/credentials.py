"""credentials.json: where a team's (or the public) match logs are delivered.

The league's format is ``{"type": "sftp" | "s3", "credentials": {...}}``. The file is checked
against ``orchestrator/config/schemas/credentials.schema.json`` (shape), then field by field
(a numeric port, an existing key file, a well-formed pinned host key). Every problem found is
raised at once in one :class:`~orchestrator.errors.ConfigError`. Secrets live in fields with
``repr=False`` and are never printed or logged.
"""

from __future__ import annotations

import base64
import binascii
import difflib
import json
import logging
import stat
import struct
from dataclasses import dataclass, field
from functools import cache
from importlib import resources
from pathlib import Path
from typing import Any, Literal, cast

import jsonschema

from contracts import JSONObject, parse_int
from orchestrator.config.documents import CredentialsDocument, SftpDocument
from orchestrator.config.jsonfile import huge_integer_problems
from orchestrator.errors import ConfigError, Problem

__all__ = [
    "Credentials",
    "S3Credentials",
    "SftpCredentials",
    "load_credentials",
    "parse_credentials",
]

log = logging.getLogger(__name__)

SCHEMA_FILE = "credentials.schema.json"  # in orchestrator/config/schemas/
DEFAULT_SFTP_PORT = 22
DEFAULT_S3_REGION = "us-east-1"
HOST_KEY_TYPES = (
    "ssh-ed25519",
    "ssh-rsa",
    "ecdsa-sha2-nistp256",
    "ecdsa-sha2-nistp384",
    "ecdsa-sha2-nistp521",
)


@dataclass(frozen=True, slots=True, kw_only=True)
class SftpCredentials:
    """An SFTP target. ``private_key`` holds the PEM/OpenSSH text (read from the file if a path
    was given); ``host_key`` is ``"<type> <base64>"``; without ``host_key`` and ``known_hosts``
    the operator's ``~/.ssh/known_hosts`` decides."""

    source: Path
    hostname: str
    username: str
    port: int = DEFAULT_SFTP_PORT
    password: str | None = field(default=None, repr=False)
    private_key: str | None = field(default=None, repr=False)
    private_key_passphrase: str | None = field(default=None, repr=False)
    path: str = ""
    host_key: str | None = None
    known_hosts: Path | None = None
    warnings: tuple[Problem, ...] = ()
    type: Literal["sftp"] = "sftp"

    def describe(self) -> str:
        """Where the logs go, without secrets, e.g. ``sftp://team@host:22/logs``."""
        return f"sftp://{self.username}@{self.hostname}:{self.port}/{self.path.lstrip('/')}"


@dataclass(frozen=True, slots=True, kw_only=True)
class S3Credentials:
    """An S3 (or S3-compatible, with ``endpoint_url``) target."""

    source: Path
    access_id: str
    access_secret: str = field(repr=False)
    bucket: str
    region: str = DEFAULT_S3_REGION
    endpoint_url: str | None = None
    prefix: str = ""
    warnings: tuple[Problem, ...] = ()
    type: Literal["s3"] = "s3"

    def describe(self) -> str:
        """Where the logs go, without secrets, e.g. ``s3://bucket/prefix``."""
        where = f"s3://{self.bucket}/{self.prefix.strip('/')}"
        return f"{where} at {self.endpoint_url}" if self.endpoint_url else where


Credentials = SftpCredentials | S3Credentials


@cache
def _schema() -> JSONObject:
    text = (
        resources.files("orchestrator.config.schemas")
        .joinpath(SCHEMA_FILE)
        .read_text(encoding="utf-8")
    )
    schema: JSONObject = json.loads(text)
    return schema


def load_credentials(path: Path | str) -> Credentials:
    """Read and check a credentials.json file.

    Raises:
        ConfigError: with one Problem per error (file, JSON pointer, message, expected).
    """
    path = Path(path)
    name = str(path)
    try:
        text = path.read_text(encoding="utf-8")
    except OSError as exc:
        raise ConfigError(
            [Problem(name, "", f"cannot read the file: {exc.strerror or exc}", "a readable file")]
        ) from exc
    try:
        document = json.loads(text, parse_int=parse_int)
    except json.JSONDecodeError as exc:
        problem = Problem(name, "", f"not valid JSON: {exc.msg} at line {exc.lineno}", "JSON")
        raise ConfigError([problem]) from exc
    huge = huge_integer_problems(document, file=name)
    if huge:
        raise ConfigError(huge)
    warnings = _permission_warnings(path)
    try:
        credentials = parse_credentials(document, source=path, warnings=warnings)
    except ConfigError as exc:
        raise ConfigError([*exc.problems, *warnings]) from None
    for warning in credentials.warnings:
        log.warning("%s", warning)
    return credentials


def parse_credentials(
    document: Any, *, source: Path, warnings: tuple[Problem, ...] = ()
) -> Credentials:
    """Check an already parsed credentials document; relative paths resolve against ``source``."""
    name = str(source)
    problems = _schema_problems(document, name)
    if problems:
        raise ConfigError(problems)
    checked = cast("CredentialsDocument", document)  # the schema checked it
    if checked["type"] == "s3":
        body = checked["credentials"]
        return S3Credentials(
            source=source,
            access_id=body["access_id"],
            access_secret=body["access_secret"],
            bucket=body["bucket"],
            region=body.get("region", DEFAULT_S3_REGION),
            endpoint_url=body.get("endpoint_url"),
            prefix=body.get("prefix", "").strip("/"),
            warnings=warnings,
        )
    return _parse_sftp(checked["credentials"], source, warnings)


def _parse_sftp(body: SftpDocument, source: Path, warnings: tuple[Problem, ...]) -> Credentials:
    name = str(source)
    problems: list[Problem] = []
    notes = list(warnings)
    port = _parse_port(body.get("port", DEFAULT_SFTP_PORT), name, problems)
    password = body.get("password")
    key_value = body.get("private_key")
    if password is None and key_value is None:
        problems.append(
            Problem(
                name,
                "/credentials",
                "neither a password nor a private key is given",
                "'password' or 'private_key'",
            )
        )
    private_key = None
    if key_value is not None:
        private_key = _read_private_key(key_value, source, problems, notes)
    host_key = body.get("host_key")
    if host_key is not None:
        _check_host_key(host_key, name, problems)
    known_hosts = None
    if body.get("known_hosts") is not None:
        known_hosts = _resolve(source, body["known_hosts"])
        if not known_hosts.is_file():
            problems.append(
                Problem(
                    name,
                    "/credentials/known_hosts",
                    f"no such file: {known_hosts}",
                    "a known_hosts file (path relative to this file)",
                )
            )
    if host_key is None and known_hosts is None:
        notes.append(
            Problem(
                name,
                "/credentials",
                "no pinned host key: the server's key is checked "
                "against the operator's ~/.ssh/known_hosts only",
                "'host_key' (\"ssh-ed25519 AAAA...\") or 'known_hosts'",
                severity="warning",
            )
        )
    if problems:
        raise ConfigError(problems)
    return SftpCredentials(
        source=source,
        hostname=body["hostname"],
        username=body["username"],
        port=port,
        password=password,
        private_key=private_key,
        private_key_passphrase=body.get("private_key_passphrase"),
        path=body.get("path", ""),
        host_key=" ".join(host_key.split()[:2]) if host_key else None,
        known_hosts=known_hosts,
        warnings=tuple(notes),
    )


def _parse_port(value: int | str, name: str, problems: list[Problem]) -> int:
    expected = "an integer from 1 to 65535 (or a string of digits)"
    if isinstance(value, str):
        if not value.strip().isdigit():
            problems.append(
                Problem(name, "/credentials/port", f"{value!r} is not a port number", expected)
            )
            return DEFAULT_SFTP_PORT
        value = int(value.strip())
    if not 1 <= value <= 65535:
        problems.append(Problem(name, "/credentials/port", f"{value} is out of range", expected))
        return DEFAULT_SFTP_PORT
    return value


def _read_private_key(
    value: str, source: Path, problems: list[Problem], notes: list[Problem]
) -> str | None:
    name = str(source)
    pointer = "/credentials/private_key"
    expected = "a private key file (path relative to this file) or the key's PEM text"
    if value.lstrip().startswith("-----BEGIN"):
        text = value
    else:
        key_path = _resolve(source, value)
        try:
            text = key_path.read_text(encoding="utf-8")
        except (OSError, UnicodeDecodeError) as exc:
            problems.append(
                Problem(name, pointer, f"cannot read key file {key_path}: {exc}", expected)
            )
            return None
        notes.extend(_permission_warnings(key_path, report_as=name, pointer=pointer))
    if "PRIVATE KEY-----" not in text:
        problems.append(Problem(name, pointer, "this is not a private key", expected))
        return None
    return text


def _check_host_key(value: str, name: str, problems: list[Problem]) -> None:
    pointer = "/credentials/host_key"
    expected = "'<type> <base64>' as in known_hosts, e.g. \"ssh-ed25519 AAAA...\""
    key_type, blob_b64 = value.split()[:2]
    try:
        blob = base64.b64decode(blob_b64, validate=True)
        (length,) = struct.unpack(">I", blob[:4])
        embedded = blob[4 : 4 + length].decode("ascii")
    except (binascii.Error, struct.error, UnicodeDecodeError):
        problems.append(
            Problem(name, pointer, "the key data is not a valid SSH public key", expected)
        )
        return
    if embedded != key_type:
        problems.append(
            Problem(name, pointer, f"the key data is a {embedded} key, not {key_type}", expected)
        )


def _schema_problems(document: Any, name: str) -> list[Problem]:
    validator = jsonschema.Draft202012Validator(_schema())
    problems = []
    for error in sorted(validator.iter_errors(document), key=lambda e: list(e.absolute_path)):
        problems.append(_problem_from(error, name))
    return problems


def _problem_from(error: jsonschema.ValidationError, name: str) -> Problem:
    pointer = "".join(f"/{part}" for part in error.absolute_path)
    validator = error.validator
    if validator == "additionalProperties":
        allowed = sorted(error.schema.get("properties", {}))
        extra = sorted(set(error.instance) - set(allowed))
        suggestion = ""
        if extra:
            close = difflib.get_close_matches(extra[0], allowed, n=1)
            suggestion = repr(close[0]) if close else ""
        return Problem(
            name,
            f"{pointer}/{extra[0]}" if extra else pointer,
            "unknown field",
            f"one of {', '.join(allowed)}",
            suggestion,
        )
    if validator == "required":
        missing = str(error.message).split("'")[1]
        return Problem(name, f"{pointer}/{missing}", "missing required field", f"'{missing}'")
    if validator == "enum":
        options = ", ".join(repr(v) for v in error.validator_value)
        close = difflib.get_close_matches(str(error.instance), error.validator_value, n=1)
        return Problem(
            name,
            pointer,
            f"{error.instance!r} is not allowed",
            f"one of {options}",
            repr(close[0]) if close else "",
        )
    if validator == "type":
        expected = error.validator_value
        if isinstance(expected, list):
            expected = " or ".join(expected)
        return Problem(name, pointer, f"{error.instance!r} has the wrong type", str(expected))
    if validator == "pattern":
        title = error.schema.get("description", f"a value matching {error.validator_value}")
        return Problem(name, pointer, f"{error.instance!r} is malformed", title)
    if validator == "minLength":
        return Problem(name, pointer, "must not be empty", "a non-empty string")
    return Problem(name, pointer, error.message)


def _resolve(source: Path, value: str) -> Path:
    candidate = Path(value).expanduser()
    return candidate if candidate.is_absolute() else source.parent / candidate


def _permission_warnings(
    path: Path, *, report_as: str | None = None, pointer: str = ""
) -> tuple[Problem, ...]:
    try:
        mode = stat.S_IMODE(path.stat().st_mode)
    except OSError:
        return ()
    if mode & 0o077 == 0:
        return ()
    return (
        Problem(
            report_as or str(path),
            pointer,
            f"{path} holds secrets but is readable by group or others (mode {mode:04o})",
            f"mode 0600 (chmod 600 {path})",
            severity="warning",
        ),
    )
