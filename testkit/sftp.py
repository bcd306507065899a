"""SFTP servers on 127.0.0.1 for integration tests and the delivery benchmark.

* :class:`SshdServer` (root): OpenSSH ``sshd`` with its own config, a chroot and an SFTP-only
  system user created for it (``hlvs-sftp-<pid>-<random>``) and removed by :meth:`SshdServer.stop`.
  Everything lives under ``/srv/hlvs-test/`` (sshd wants root-owned chroot and key paths, not
  under /tmp). The chroot holds ``upload/`` (writable by the user) and ``readonly/`` (not).
* :class:`AsyncsshServer` (any user): asyncssh's SFTP server in a thread, chrooted to a folder.

Both accept the password and the public key given to ``start`` and present a fresh ed25519
host key, whose ``"<type> <base64>"`` is :attr:`host_key`.
"""

from __future__ import annotations

import asyncio
import logging
import os
import pwd
import secrets
import shutil
import signal
import socket
import subprocess
import threading
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

__all__ = ["AsyncsshServer", "SftpServer", "SshdServer", "free_port", "generate_key", "start"]

log = logging.getLogger(__name__)

SSHD = "/usr/sbin/sshd"
SRV_ROOT = Path("/srv/hlvs-test")


def free_port() -> int:
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        port: int = sock.getsockname()[1]
        return port


def wait_for_port(port: int, timeout_s: float = 20.0) -> None:
    deadline = time.monotonic() + timeout_s
    while True:
        try:
            with socket.create_connection(("127.0.0.1", port), timeout=1.0):
                return
        except OSError as exc:
            if time.monotonic() > deadline:
                message = f"nothing listens on 127.0.0.1:{port} after {timeout_s} s"
                raise TimeoutError(message) from exc
            time.sleep(0.05)


def generate_key(path: Path) -> tuple[str, str]:
    """Make an ed25519 key pair at ``path``; returns (private PEM text, "type base64" public)."""
    subprocess.run(
        ["ssh-keygen", "-q", "-t", "ed25519", "-N", "", "-C", "", "-f", str(path)], check=True
    )
    public = path.with_name(path.name + ".pub").read_text().split()
    return path.read_text(), f"{public[0]} {public[1]}"


@dataclass
class SftpServer:
    """What every local SFTP server offers to tests: where it listens and how to log in."""

    port: int
    username: str
    password: str = field(repr=False)
    host_key: str
    client_key: str = field(repr=False)  # private key (PEM) accepted for ``username``
    root: Path  # the chroot on the local disk
    upload_path: str = "/upload"  # writable folder, as the client sees it
    readonly_path: str = "/readonly"  # not writable by the user

    def stop(self) -> None:
        raise NotImplementedError

    def start_again(self) -> None:
        """Listen again on the same port with the same keys and files (after :meth:`kill`)."""
        raise NotImplementedError

    def kill(self) -> None:
        """Drop the server and every open session at once, like a crash."""
        raise NotImplementedError


def start(workdir: Path) -> SftpServer:
    """An sshd server when running as root, else an asyncssh server."""
    return SshdServer.start() if os.geteuid() == 0 else AsyncsshServer.start(workdir)


@dataclass
class SshdServer(SftpServer):
    home: Path = Path()
    process: subprocess.Popen[bytes] | None = None

    @classmethod
    def start(cls) -> SshdServer:
        token = secrets.token_hex(2)
        home = SRV_ROOT / f"sshd-{os.getpid()}-{token}"
        username = f"hlvs-sftp-{os.getpid()}-{token}"
        try:
            server = cls._prepare(home, username)
            server.start_again()
        except BaseException:
            subprocess.run(["userdel", username], check=False, capture_output=True)
            shutil.rmtree(home, ignore_errors=True)
            raise
        return server

    @classmethod
    def _prepare(cls, home: Path, username: str) -> SshdServer:
        password = secrets.token_urlsafe(12)
        chroot = home / "chroot"
        (chroot / "readonly").mkdir(parents=True)
        SRV_ROOT.chmod(0o755)
        home.chmod(0o755)
        _ensure_user(username, password)
        user = pwd.getpwnam(username)
        (chroot / "upload").mkdir()
        os.chown(chroot / "upload", user.pw_uid, user.pw_gid)
        _, host_key = generate_key(home / "host_key")
        client_key, client_public = generate_key(home / "client_key")
        (home / "authorized_keys").write_text(client_public + "\n")
        (home / "authorized_keys").chmod(0o644)
        port = free_port()
        (home / "sshd_config").write_text(_sshd_config(home, port, username))
        Path("/run/sshd").mkdir(mode=0o755, exist_ok=True)
        return cls(
            port=port,
            username=username,
            password=password,
            host_key=host_key,
            client_key=client_key,
            root=chroot,
            home=home,
        )

    def start_again(self) -> None:
        with (self.home / "sshd.log").open("ab") as log_file:
            self.process = subprocess.Popen(
                [SSHD, "-D", "-e", "-f", str(self.home / "sshd_config")],
                stdout=subprocess.DEVNULL,
                stderr=log_file,
                start_new_session=True,
            )
        wait_for_port(self.port)

    def kill(self) -> None:
        if self.process is None:
            return
        for pid in [*_descendants(self.process.pid), self.process.pid]:
            try:
                os.kill(pid, signal.SIGKILL)
            except ProcessLookupError:
                pass
        self.process.wait(timeout=10)
        self.process = None

    def stop(self) -> None:
        self.kill()
        subprocess.run(["userdel", self.username], check=False, capture_output=True)
        shutil.rmtree(self.home, ignore_errors=True)


def _sshd_config(home: Path, port: int, username: str) -> str:
    return f"""\
Port {port}
ListenAddress 127.0.0.1
HostKey {home}/host_key
PidFile {home}/sshd.pid
AuthorizedKeysFile {home}/authorized_keys
PasswordAuthentication yes
KbdInteractiveAuthentication no
PubkeyAuthentication yes
UsePAM no
PermitRootLogin no
AllowUsers {username}
MaxStartups 50
LogLevel INFO
Subsystem sftp internal-sftp
Match User {username}
    ChrootDirectory {home}/chroot
    ForceCommand internal-sftp
    AllowTcpForwarding no
    X11Forwarding no
"""


def _ensure_user(username: str, password: str) -> None:
    try:
        pwd.getpwnam(username)
    except KeyError:
        subprocess.run(
            [
                "useradd",
                "--system",
                "--no-create-home",
                "--home-dir",
                "/",
                "--shell",
                "/usr/sbin/nologin",
                username,
            ],
            check=True,
            capture_output=True,
        )
    subprocess.run(["chpasswd"], input=f"{username}:{password}".encode(), check=True)


def _descendants(pid: int) -> list[int]:
    children: dict[int, list[int]] = {}
    for entry in Path("/proc").iterdir():
        if not entry.name.isdigit():
            continue
        try:
            stat_text = (entry / "stat").read_text()
        except OSError:
            continue
        ppid = int(stat_text.rsplit(")", 1)[1].split()[1])
        children.setdefault(ppid, []).append(int(entry.name))
    found: list[int] = []
    todo = [pid]
    while todo:
        for child in children.get(todo.pop(), []):
            found.append(child)
            todo.append(child)
    return found


@dataclass
class AsyncsshServer(SftpServer):
    loop: asyncio.AbstractEventLoop | None = None
    thread: threading.Thread | None = None
    acceptor: Any = None
    connections: list[Any] = field(default_factory=list)
    home: Path = Path()

    @classmethod
    def start(cls, workdir: Path) -> AsyncsshServer:
        home = workdir / f"asyncssh-{secrets.token_hex(3)}"
        chroot = home / "chroot"
        (chroot / "upload").mkdir(parents=True)
        (chroot / "readonly").mkdir()
        (chroot / "readonly").chmod(0o555)
        _, host_key = generate_key(home / "host_key")
        client_key, client_public = generate_key(home / "client_key")
        (home / "authorized_keys").write_text(client_public + "\n")
        loop = asyncio.new_event_loop()
        thread = threading.Thread(target=loop.run_forever, name="asyncssh-sftp", daemon=True)
        thread.start()
        server = cls(
            port=free_port(),
            username="hlvs",
            password=secrets.token_urlsafe(12),
            host_key=host_key,
            client_key=client_key,
            root=chroot,
            loop=loop,
            thread=thread,
            home=home,
        )
        server.start_again()
        return server

    def start_again(self) -> None:
        assert self.loop is not None
        future = asyncio.run_coroutine_threadsafe(self._listen(), self.loop)
        self.acceptor = future.result(timeout=20)

    async def _listen(self) -> Any:
        import asyncssh

        server = self
        root = str(self.root).encode()

        class Auth(asyncssh.SSHServer):
            def connection_made(self, conn: Any) -> None:
                server.connections.append(conn)

            def password_auth_supported(self) -> bool:
                return True

            def validate_password(self, username: str, password: str) -> bool:
                return username == server.username and password == server.password

        return await asyncssh.listen(
            "127.0.0.1",
            self.port,
            server_factory=Auth,
            server_host_keys=[str(self.home / "host_key")],
            authorized_client_keys=str(self.home / "authorized_keys"),
            sftp_factory=lambda chan: asyncssh.SFTPServer(chan, chroot=root),
            allow_scp=False,
        )

    def kill(self) -> None:
        assert self.loop is not None

        async def drop() -> None:
            if self.acceptor is not None:
                self.acceptor.close()
            for conn in self.connections:
                conn.abort()
            self.connections.clear()

        asyncio.run_coroutine_threadsafe(drop(), self.loop).result(timeout=10)
        self.acceptor = None

    def stop(self) -> None:
        self.kill()
        assert self.loop is not None and self.thread is not None
        self.loop.call_soon_threadsafe(self.loop.stop)
        self.thread.join(timeout=10)
        (self.root / "readonly").chmod(0o755)
        shutil.rmtree(self.home, ignore_errors=True)
