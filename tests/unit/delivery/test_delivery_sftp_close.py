"""Closing an SFTP session whose server died must not raise (the retry opens a new one)."""

from __future__ import annotations

from typing import Any, cast

from orchestrator.delivery.sftp import SftpUploader


class _DeadChannel:
    def close(self) -> None:
        raise EOFError  # what paramiko raises when the close message cannot be sent


class _Transport:
    closed = False

    def close(self) -> None:
        self.closed = True


def test_close_after_the_server_died_closes_the_transport_without_raising() -> None:
    transport = _Transport()
    uploader = SftpUploader(
        transport=cast(Any, transport),
        client=cast(Any, _DeadChannel()),
        credentials=cast(Any, type("C", (), {"path": "/upload"})()),
        team="Alpha",
    )
    uploader.close()
    assert transport.closed
