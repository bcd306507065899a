"""Delivering log sets to real SFTP servers on 127.0.0.1 (OpenSSH sshd; asyncssh without root)."""

from __future__ import annotations

import json
import os
import threading
import time
from pathlib import Path
from typing import Any

import pytest

from orchestrator.delivery import deliver_pending, enqueue_match_logs, pending_status
from testkit.sftp import (
    AsyncsshServer,
    SftpServer,
    SshdServer,
    free_port,
    generate_key,
)
from tests.integration.delivery.conftest import (
    FAST_RETRY,
    check_manifest,
    make_match,
    read_tree,
    robot_files,
    write_credentials,
)

# a valid ed25519 public key that belongs to none of the test servers
OTHER_KEY = "ssh-ed25519 AAAAC3NzaC1lZDI1NTE5AAAAILxD7/6Y8WqDP6ruY81+KhRD3hE1yx9rKAmI0vF5eFKN"


def sftp_body(server: SftpServer, **overrides: Any) -> dict[str, Any]:
    body: dict[str, Any] = {
        "hostname": "127.0.0.1",
        "port": str(server.port),
        "username": server.username,
        "password": server.password,
        "path": f"{server.upload_path}/hlvs",
        "host_key": server.host_key,
    }
    body.update(overrides)
    return {k: v for k, v in body.items() if v is not None}


def deliver_one(tmp_path: Path, body: dict[str, Any], match_id: str = "m1") -> Any:
    creds = write_credentials(tmp_path, "sftp", body)
    store = tmp_path / "store"
    match = make_match(tmp_path, match_id, robot_files())
    enqueue_match_logs(
        match, match_id=match_id, teams={"red": ("Alpha", creds)}, public_target=None, store=store
    )
    [outcome] = deliver_pending(store, retry=FAST_RETRY)
    return outcome, store


@pytest.mark.root
def test_password_delivery_with_manifest(sshd: SshdServer, tmp_path: Path) -> None:
    outcome, store = deliver_one(tmp_path, sftp_body(sshd), "pw-match")
    assert outcome.delivered, outcome.error
    assert pending_status(store) == []
    remote = read_tree(sshd.root / "upload" / "hlvs")
    manifest = check_manifest(remote, "pw-match/Alpha")
    assert len(manifest["files"]) == 5
    assert not [k for k in remote if k.endswith(".part")]
    assert os.stat(sshd.root / "upload" / "hlvs" / "pw-match").st_uid != 0  # written by the user


@pytest.mark.root
def test_key_delivery_and_known_hosts_file(sshd: SshdServer, tmp_path: Path) -> None:
    known_hosts = tmp_path / "known_hosts"
    known_hosts.write_text(f"[127.0.0.1]:{sshd.port} {sshd.host_key}\n")
    body = sftp_body(
        sshd, password=None, private_key=sshd.client_key, host_key=None, known_hosts="known_hosts"
    )
    outcome, _ = deliver_one(tmp_path, body, "key-match")
    assert outcome.delivered, outcome.error
    check_manifest(read_tree(sshd.root / "upload" / "hlvs"), "key-match/Alpha")


@pytest.mark.root
@pytest.mark.parametrize(
    ("case", "kind"),
    [
        ("wrong_password", "auth"),
        ("wrong_key", "auth"),
        ("host_key_mismatch", "host_key"),
        ("host_key_unknown", "host_key"),
        ("path_not_writable", "path"),
    ],
)
def test_errors_a_team_can_act_on(sshd: SshdServer, tmp_path: Path, case: str, kind: str) -> None:
    other_key, other_public = generate_key(tmp_path / "other")
    (tmp_path / "empty_known_hosts").write_text("")
    body = {
        "wrong_password": sftp_body(sshd, password="not-the-password"),
        "wrong_key": sftp_body(sshd, password=None, private_key=other_key),
        "host_key_mismatch": sftp_body(sshd, host_key=other_public),
        "host_key_unknown": sftp_body(sshd, host_key=None, known_hosts="empty_known_hosts"),
        "path_not_writable": sftp_body(sshd, path=f"{sshd.readonly_path}/hlvs"),
    }[case]
    started = time.monotonic()
    outcome, store = deliver_one(tmp_path, body)
    assert not outcome.delivered and outcome.error is not None
    assert outcome.error.kind == kind and outcome.error.team == "Alpha"
    assert time.monotonic() - started < 10  # not retried
    [pending] = pending_status(store)
    assert pending.last_error is not None and pending.last_error.kind == kind
    assert sshd.password not in str(outcome.error)


def test_unreachable_server(tmp_path: Path) -> None:
    server = SftpServer(
        port=free_port(),
        username="u",
        password="p",
        host_key="ssh-ed25519 AAAAC3NzaC1lZDI1NTE5AAAAILxD7/6Y8WqDP6ruY81+KhRD3hE1yx9rKAmI0vF5eFKN",
        client_key="",
        root=tmp_path,
    )
    outcome, store = deliver_one(tmp_path, sftp_body(server))
    assert outcome.error is not None and outcome.error.kind == "unreachable"
    assert len(pending_status(store)) == 1


@pytest.mark.root
def test_server_dies_mid_transfer_and_the_next_delivery_completes(
    sshd: SshdServer, tmp_path: Path
) -> None:
    files = robot_files()
    files["red-2/robocup-logs/big.bin"] = os.urandom(96 << 20)
    creds = write_credentials(tmp_path, "sftp", sftp_body(sshd))
    store = tmp_path / "store"
    enqueue_match_logs(
        make_match(tmp_path, "crash", files),
        match_id="crash",
        teams={"red": ("Alpha", creds)},
        public_target=None,
        store=store,
    )
    team_dir = sshd.root / "upload" / "hlvs" / "crash" / "Alpha"
    killed = threading.Event()

    def kill_when_partial() -> None:
        partial = team_dir / "red-2" / "robocup-logs" / ".big.bin.part"
        deadline = time.monotonic() + 60
        while time.monotonic() < deadline:
            try:
                size = partial.stat().st_size
            except OSError:
                size = 0
            if size > (1 << 20):  # well inside the transfer of the big file
                sshd.kill()
                killed.set()
                return
            time.sleep(0.005)

    killer = threading.Thread(target=kill_when_partial)
    killer.start()
    try:
        [outcome] = deliver_pending(store, retry=FAST_RETRY)
    finally:
        killer.join()
        if not killed.is_set() or sshd.process is None:
            sshd.start_again()
    assert killed.is_set(), "the big file was never seen in transfer"
    assert not outcome.delivered and outcome.error is not None, outcome
    assert outcome.error.kind in ("transient", "unreachable")
    assert not (team_dir / "MANIFEST.json").exists()
    assert not (team_dir / "red-2" / "robocup-logs" / "big.bin").exists()
    [again] = deliver_pending(store, retry=FAST_RETRY)
    assert again.delivered, again.error
    assert again.skipped_files >= 1  # what arrived before the crash is not sent twice
    remote = read_tree(sshd.root / "upload" / "hlvs")
    check_manifest(remote, "crash/Alpha")
    assert not [k for k in remote if k.endswith(".part")]


def test_asyncssh_server_password_and_host_key_mismatch(
    asyncssh_server: AsyncsshServer, tmp_path: Path
) -> None:
    (tmp_path / "ok").mkdir()
    outcome, _ = deliver_one(tmp_path / "ok", sftp_body(asyncssh_server), "as-match")
    assert outcome.delivered, outcome.error
    check_manifest(read_tree(asyncssh_server.root / "upload" / "hlvs"), "as-match/Alpha")
    (tmp_path / "bad").mkdir()
    outcome, _ = deliver_one(tmp_path / "bad", sftp_body(asyncssh_server, host_key=OTHER_KEY))
    assert outcome.error is not None and outcome.error.kind == "host_key"


def test_cli_status_and_deliver(
    asyncssh_server: AsyncsshServer, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    from hlvs.cli import main

    creds = write_credentials(tmp_path, "sftp", sftp_body(asyncssh_server))
    bad = write_credentials(
        tmp_path, "sftp", sftp_body(asyncssh_server, password="wrong"), "bad.json"
    )
    store = tmp_path / "store"
    for match_id, target in (("cli-1", creds), ("cli-2", bad)):
        enqueue_match_logs(
            make_match(tmp_path, match_id, robot_files()),
            match_id=match_id,
            teams={"red": ("Alpha", target)},
            public_target=None,
            store=store,
        )
    assert main(["logs", "status", "--store", str(store)]) == 0
    out = capsys.readouterr().out
    assert "cli-1 Alpha: 5 files" in out and "cli-2 Alpha" in out
    assert main(["logs", "deliver", "--store", str(store)]) == 1
    out = capsys.readouterr().out
    assert "delivered cli-1 Alpha" in out
    assert "FAILED cli-2 Alpha" in out and "(auth:" in out and "wrong" not in out
    assert main(["logs", "status", "--store", str(store), "--json"]) == 0
    [left] = json.loads(capsys.readouterr().out)
    assert left["match_id"] == "cli-2" and left["last_error"]["kind"] == "auth"


def test_a_server_that_never_answers_times_out_and_is_retried(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, caplog: pytest.LogCaptureFixture
) -> None:
    import logging
    import socket

    from orchestrator.delivery import sftp

    monkeypatch.setattr(sftp, "CONNECT_TIMEOUT_S", 0.5)
    with socket.socket() as silent:  # accepts connections (backlog) but never speaks
        silent.bind(("127.0.0.1", 0))
        silent.listen(8)
        server = SftpServer(
            port=silent.getsockname()[1],
            username="u",
            password="p",
            host_key=OTHER_KEY,
            client_key="",
            root=tmp_path,
        )
        started = time.monotonic()
        with caplog.at_level(logging.INFO):
            outcome, store = deliver_one(tmp_path, sftp_body(server))
            time.sleep(0.3)  # paramiko's reading threads end after the close
    assert outcome.error is not None and outcome.error.kind == "transient"
    # the failure is the outcome's, said once: no traceback of paramiko's reading thread
    assert [r.getMessage() for r in caplog.records
            if r.name.startswith("paramiko") and r.levelno >= logging.WARNING] == []
    assert 1.0 <= time.monotonic() - started < 10  # two attempts of 0.5 s each
    assert pending_status(store)[0].last_error.kind == "transient"  # type: ignore[union-attr]


def test_with_address_rules_the_host_is_resolved_and_the_connection_pinned(
    asyncssh_server: AsyncsshServer, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The service's opener (``allowed``): the SFTP host name is resolved and checked once
    and the connection goes to that address; refused (kind ``address``) when it resolves to
    a network that is not allowed, before anything is sent."""
    import ipaddress
    import socket

    from orchestrator.config.credentials import parse_credentials
    from orchestrator.delivery import open_uploader
    from orchestrator.errors import DeliveryError

    real = socket.getaddrinfo
    looked_up: list[str] = []

    def getaddrinfo(host: Any, *args: Any, **kwargs: Any) -> Any:
        if host == "sftp.example.org":
            looked_up.append(host)
            return real("127.0.0.1", *args, **kwargs)
        return real(host, *args, **kwargs)

    connected: list[Any] = []
    real_connect = socket.create_connection

    def create_connection(address: Any, *args: Any, **kwargs: Any) -> Any:
        connected.append(address[0])
        return real_connect(address, *args, **kwargs)

    monkeypatch.setattr(socket, "getaddrinfo", getaddrinfo)
    monkeypatch.setattr(socket, "create_connection", create_connection)
    document = {"type": "sftp", "credentials": sftp_body(asyncssh_server,
                                                         hostname="sftp.example.org")}
    credentials = parse_credentials(document, source=Path("credentials.json"))
    uploader = open_uploader(credentials, "Alpha",
                             allowed=(ipaddress.ip_network("127.0.0.1/32"),))
    uploader.close()
    assert looked_up == ["sftp.example.org"] and connected == ["127.0.0.1"]
    connected.clear()
    with pytest.raises(DeliveryError) as refused:
        open_uploader(credentials, "Alpha", allowed=())
    assert refused.value.kind == "address" and connected == []
    assert "sftp.example.org is 127.0.0.1, not a public address" in refused.value.reason
