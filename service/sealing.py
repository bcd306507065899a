"""A team's secrets, sealed at rest: encrypted in the database, the key kept outside it.

What is sealed: a team file's registry password and ECR secret key, the password, secret key,
private key and passphrase of credentials.json, and a team's webhook secret. Each such value is
stored as ``enc:v1:<Fernet token>`` (AES-128-CBC + HMAC-SHA256) and opened only where it is used
(the files of a match, the pre-flight, log delivery, webhook signing); every other reader sees
the sealed text, never the secret.

The key: ``HLVS_SERVICE_SECRET_KEY`` (a Fernet key, set by the operator), else the key file
``HLVS_SERVICE_SECRET_KEY_FILE`` (default: ``<data_dir>.key``, next to the data folder), created
0600 with a fresh key on the first start. A database copied without its key holds no secret.
"""

from __future__ import annotations

import copy
import logging
import os
import stat
from pathlib import Path
from typing import Any

from cryptography.fernet import Fernet, InvalidToken

from orchestrator import private_dir
from service.errors import SettingsError

log = logging.getLogger(__name__)

PREFIX = "enc:v1:"

SECRET_FIELDS: dict[str, tuple[tuple[str, ...], ...]] = {
    "team_config": (("registry_auth", "password"), ("registry_auth", "ecr", "access_secret")),
    "credentials": (("credentials", "password"), ("credentials", "access_secret"),
                    ("credentials", "private_key"), ("credentials", "private_key_passphrase")),
}
"""Where a secret sits in each kind of team file (JSON object keys from the root)."""


class Sealer:
    """Seals and opens secret strings with one key."""

    def __init__(self, key: bytes) -> None:
        try:
            self._fernet = Fernet(key)
        except ValueError as exc:
            raise SettingsError(name="HLVS_SERVICE_SECRET_KEY", value="(hidden)",
                                expected="a Fernet key: 32 bytes, url-safe base64") from exc

    def seal(self, secret: str) -> str:
        if secret.startswith(PREFIX):
            return secret
        return PREFIX + self._fernet.encrypt(secret.encode("utf-8")).decode("ascii")

    def open(self, value: str) -> str:
        """The secret of a sealed value (a value stored before sealing existed is returned
        as it is)."""
        if not value.startswith(PREFIX):
            return value
        try:
            return self._fernet.decrypt(value[len(PREFIX):].encode("ascii")).decode("utf-8")
        except InvalidToken as exc:
            raise SettingsError(name="HLVS_SERVICE_SECRET_KEY", value="(hidden)",
                                expected="the key the stored secrets were sealed with") from exc

    def seal_document(self, kind: str, document: Any) -> Any:
        """A copy of a team file with its secrets sealed."""
        return _map_secrets(kind, document, self.seal)

    def open_document(self, kind: str, document: Any) -> Any:
        """A copy of a stored team file with its secrets opened (for a match or a delivery)."""
        return _map_secrets(kind, document, self.open)


def _map_secrets(kind: str, document: Any, change: Any) -> Any:
    out = copy.deepcopy(document)
    for path in SECRET_FIELDS.get(kind, ()):
        holder = out
        for key in path[:-1]:
            holder = holder.get(key) if isinstance(holder, dict) else None
        if isinstance(holder, dict) and isinstance(holder.get(path[-1]), str):
            holder[path[-1]] = change(holder[path[-1]])
    return out


def is_sealed(value: object) -> bool:
    return isinstance(value, str) and value.startswith(PREFIX)


def key_file(data_dir: Path, configured: str) -> Path:
    """Where the key file is: the configured path, else ``<data_dir>.key`` beside the folder."""
    if configured:
        return Path(configured)
    data_dir = data_dir.resolve()
    return data_dir.parent / (data_dir.name + ".key")


def load_sealer(*, key: str, key_path: Path) -> Sealer:
    """The service's sealer: from ``key`` when the operator set one, else from ``key_path``
    (created 0600 with a new key when missing; a key file others can read is made 0600)."""
    if key:
        return Sealer(key.encode("ascii", "replace"))
    private_dir(key_path.parent, only_if_new=True)
    try:
        fd = os.open(key_path, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o600)
    except FileExistsError:
        mode = stat.S_IMODE(key_path.stat().st_mode)
        if mode & 0o077:
            log.warning("the key file %s was readable by others (mode %04o); now 0600",
                        key_path, mode)
            key_path.chmod(0o600)
        return Sealer(key_path.read_bytes().strip())
    with os.fdopen(fd, "wb") as handle:
        handle.write(Fernet.generate_key() + b"\n")
    log.info("a new key for the stored secrets was written to %s (keep it with the database "
             "backups, apart from them)", key_path)
    return Sealer(key_path.read_bytes().strip())


__all__ = ["PREFIX", "SECRET_FIELDS", "Sealer", "is_sealed", "key_file", "load_sealer"]
