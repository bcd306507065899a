"""SFTP uploader (the only paramiko user of the delivery package).

The server's host key is checked against the pinned ``host_key``, else the ``known_hosts`` file
of the credentials, else the operator's ``~/.ssh/known_hosts``; an unknown key is refused (no
auto-add). Files are written to ``.<name>.part`` and renamed into place, so a file with its final
name is always complete.

A session's failure is reported once, as a :class:`DeliveryError` naming the team and the
target; paramiko's own warnings and errors from the session's reading thread (the traceback it
logs when a silent server's banner never comes, or the socket is closed under it) go to this
module's log at debug level.
"""

from __future__ import annotations

import base64
import errno
import io
import logging
import posixpath
import socket
import stat
import threading
from pathlib import Path
from typing import Protocol

import paramiko

from orchestrator.config.credentials import SftpCredentials
from orchestrator.delivery.addresses import AddressRefused, IPNetwork, resolve
from orchestrator.errors import DeliveryError

__all__ = ["SftpUploader"]

log = logging.getLogger(__name__)

CONNECT_TIMEOUT_S = 10.0
IO_TIMEOUT_S = 30.0
WINDOW_BYTES = 8 << 20
_OURS = "hlvs_session"  # set on the transports this module opens


class _ReportedByUs(logging.Filter):
    """paramiko's warnings and errors from the reading thread of a transport this module
    opened go to this module's log at debug level: every failure of such a session reaches
    the caller as a :class:`DeliveryError` (a traceback of paramiko's besides it, when a
    silent server's banner never came, said the same thing twice)."""

    def filter(self, record: logging.LogRecord) -> bool:
        if record.levelno < logging.WARNING:
            return True
        thread = next((t for t in threading.enumerate() if t.ident == record.thread), None)
        if not getattr(thread, _OURS, False):
            return True
        log.debug("SSH session (%s): %s", record.levelname.lower(), record.getMessage())
        return False


logging.getLogger("paramiko.transport").addFilter(_ReportedByUs())


_KEY_CLASSES: tuple[type[paramiko.PKey], ...] = (
    paramiko.Ed25519Key,
    paramiko.ECDSAKey,
    paramiko.RSAKey,
)


class _Fail(Protocol):
    def __call__(self, kind: str, reason: str) -> DeliveryError: ...


class SftpUploader:
    """An open SFTP session; use :meth:`connect`."""

    def __init__(
        self,
        *,
        transport: paramiko.Transport,
        client: paramiko.SFTPClient,
        credentials: SftpCredentials,
        team: str,
    ) -> None:
        self._transport = transport
        self._client = client
        self._credentials = credentials
        self._team = team
        self._base = credentials.path.rstrip("/") or "."
        self._made: set[str] = set()

    @property
    def target(self) -> str:
        return self._credentials.describe()

    @classmethod
    def connect(cls, credentials: SftpCredentials, *, team: str,
                allowed: tuple[IPNetwork, ...] | None = None,
                allow_setting: str = "") -> SftpUploader:
        """Open a session; with ``allowed``, to the checked address of the host name only
        (:func:`orchestrator.delivery.targets.open_uploader`)."""
        target = credentials.describe()

        def fail(kind: str, reason: str) -> DeliveryError:
            return DeliveryError(team=team, target=target, kind=kind, reason=reason)

        host = credentials.hostname
        if allowed is not None:
            try:
                host = str(resolve(credentials.hostname, credentials.port, allowed,
                                   allow_setting))
            except AddressRefused as exc:
                raise fail("address", str(exc)) from None
        try:
            sock = socket.create_connection((host, credentials.port), timeout=CONNECT_TIMEOUT_S)
        except socket.gaierror as exc:
            raise fail("unreachable", f"unknown host name: {exc.strerror}") from exc
        except OSError as exc:
            raise fail("unreachable", f"cannot connect: {exc.strerror or exc}") from exc
        transport = paramiko.Transport(sock, default_window_size=WINDOW_BYTES)
        setattr(transport, _OURS, True)
        transport.banner_timeout = CONNECT_TIMEOUT_S
        transport.auth_timeout = CONNECT_TIMEOUT_S
        try:
            known = _expected_keys(credentials)
            if known:
                options = transport.get_security_options()
                preferred = _algorithms_for(known)
                options.key_types = preferred + [t for t in options.key_types if t not in preferred]
            transport.start_client(timeout=CONNECT_TIMEOUT_S)
            _check_host_key(transport.get_remote_server_key(), known, credentials, fail)
            _authenticate(transport, credentials, fail)
            client = paramiko.SFTPClient.from_transport(transport)
            if client is None:
                raise fail("transient", "the server opened no SFTP channel")
            client.get_channel().settimeout(IO_TIMEOUT_S)  # type: ignore[union-attr]
        except DeliveryError:
            transport.close()
            raise
        except (paramiko.SSHException, OSError, EOFError) as exc:
            transport.close()
            raise fail("transient", f"SSH connection failed: {exc}") from exc
        log.info("team %s: connected to %s", team, target)
        return cls(transport=transport, client=client, credentials=credentials, team=team)

    def upload(self, local_path: Path, remote_rel_path: str) -> None:
        remote = posixpath.join(self._base, remote_rel_path)
        folder, name = posixpath.split(remote)
        partial = posixpath.join(folder, f".{name}.part")
        try:
            self._mkdir_p(folder)
            self._client.put(str(local_path), partial, confirm=True)
            try:
                self._client.posix_rename(partial, remote)
            except OSError:
                self._remove_if_present(remote)
                self._client.rename(partial, remote)
        except (OSError, paramiko.SSHException, EOFError) as exc:
            raise self._translate(exc, remote) from exc

    def exists(self, remote_rel_path: str, size: int) -> bool:
        remote = posixpath.join(self._base, remote_rel_path)
        try:
            attributes = self._client.stat(remote)
        except FileNotFoundError:
            return False
        except (OSError, paramiko.SSHException, EOFError) as exc:
            raise self._translate(exc, remote) from exc
        return stat.S_ISREG(attributes.st_mode or 0) and attributes.st_size == size

    def close(self) -> None:
        """Best effort: after a server died mid-transfer, closing the channel cannot be sent
        (paramiko raises EOFError); the transport is closed all the same."""
        try:
            self._client.close()
        except (OSError, paramiko.SSHException, EOFError) as exc:
            log.debug("closing the SFTP channel to a dead connection: %r", exc)
        finally:
            self._transport.close()

    def _mkdir_p(self, folder: str) -> None:
        if folder in ("", ".", "/") or folder in self._made:
            return
        try:
            attributes = self._client.stat(folder)
        except FileNotFoundError:
            self._mkdir_p(posixpath.dirname(folder))
            try:
                self._client.mkdir(folder)
            except OSError as exc:
                if not self._is_dir(folder):  # not created meanwhile by someone else
                    raise PermissionError(
                        exc.errno or errno.EACCES, f"cannot create folder: {exc}", folder
                    ) from exc
        else:
            if not stat.S_ISDIR(attributes.st_mode or 0):
                raise NotADirectoryError(errno.ENOTDIR, "not a folder", folder)
        self._made.add(folder)

    def _is_dir(self, folder: str) -> bool:
        try:
            return stat.S_ISDIR(self._client.stat(folder).st_mode or 0)
        except FileNotFoundError:
            return False

    def _remove_if_present(self, remote: str) -> None:
        try:
            self._client.remove(remote)
        except FileNotFoundError:
            pass

    def _translate(self, exc: BaseException, remote: str) -> DeliveryError:
        target = self.target
        if isinstance(exc, PermissionError | NotADirectoryError):
            reason = f"cannot write {remote}: {exc.strerror or exc}"
            return DeliveryError(team=self._team, target=target, kind="path", reason=reason)
        if isinstance(exc, OSError) and exc.errno in (errno.EACCES, errno.EROFS, errno.ENOSPC):
            reason = f"cannot write {remote}: {exc.strerror or exc}"
            return DeliveryError(team=self._team, target=target, kind="path", reason=reason)
        reason = f"transfer of {remote} failed: {exc or type(exc).__name__}"
        return DeliveryError(team=self._team, target=target, kind="transient", reason=reason)


def _expected_keys(credentials: SftpCredentials) -> list[paramiko.PKey]:
    if credentials.host_key:
        key_type, blob = credentials.host_key.split()[:2]
        return [paramiko.PKey.from_type_string(key_type, _b64(blob))]
    files = (
        [credentials.known_hosts]
        if credentials.known_hosts
        else [Path("~/.ssh/known_hosts").expanduser()]
    )
    host_keys = paramiko.HostKeys()
    for file in files:
        if file.is_file():
            host_keys.load(str(file))
    names = [credentials.hostname] if credentials.port == 22 else []
    names.append(f"[{credentials.hostname}]:{credentials.port}")
    for name in names:
        entry = host_keys.lookup(name)
        if entry is not None:
            return [entry[key_type] for key_type in entry.keys()]
    return []


def _algorithms_for(keys: list[paramiko.PKey]) -> list[str]:
    preferred: list[str] = []
    for key in keys:
        name = key.get_name()
        names = ["rsa-sha2-512", "rsa-sha2-256", "ssh-rsa"] if name == "ssh-rsa" else [name]
        preferred.extend(n for n in names if n not in preferred)
    return preferred


def _check_host_key(
    offered: paramiko.PKey, known: list[paramiko.PKey], credentials: SftpCredentials, fail: _Fail
) -> None:
    offered_text = f"{offered.get_name()} {offered.get_base64()}"
    if not known:
        where = credentials.known_hosts or "~/.ssh/known_hosts"
        raise fail(
            "host_key",
            f"the server's host key {offered_text} is unknown: pin it as "
            f"'host_key' in {credentials.source} or add it to {where}",
        )
    if not any(
        k.get_name() == offered.get_name() and k.asbytes() == offered.asbytes() for k in known
    ):
        expected = ", ".join(f"{k.get_name()} {k.get_base64()}" for k in known)
        raise fail(
            "host_key",
            f"the server's host key {offered_text} does not match the "
            f"expected {expected} (a different server, or its key was changed)",
        )


def _authenticate(transport: paramiko.Transport, credentials: SftpCredentials, fail: _Fail) -> None:
    try:
        if credentials.private_key is not None:
            transport.auth_publickey(credentials.username, _load_key(credentials, fail))
        else:
            transport.auth_password(credentials.username, credentials.password or "")
    except paramiko.AuthenticationException as exc:
        method = "key" if credentials.private_key is not None else "password"
        raise fail(
            "auth", f"the server rejected user {credentials.username!r} with this {method}"
        ) from exc


def _load_key(credentials: SftpCredentials, fail: _Fail) -> paramiko.PKey:
    for key_class in _KEY_CLASSES:
        try:
            return key_class.from_private_key(
                io.StringIO(credentials.private_key or ""),
                password=credentials.private_key_passphrase,
            )
        except paramiko.PasswordRequiredException as exc:
            raise fail(
                "auth", "the private key is encrypted: give 'private_key_passphrase'"
            ) from exc
        except (paramiko.SSHException, ValueError):
            continue
    raise fail("auth", "the private key cannot be read (supported: ed25519, ECDSA, RSA)")


def _b64(text: str) -> bytes:
    return base64.b64decode(text)
