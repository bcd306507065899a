"""Fault modes of the stub robot, used to test how the runner copes with misbehaving robots."""

from __future__ import annotations

import errno
import logging
import os
import socket
import threading
from dataclasses import dataclass
from pathlib import Path

logger = logging.getLogger(__name__)

CHUNK_BYTES = 1 << 20
MIRROR_PORT = 3737
DATAGRAM_BYTES = 1400


@dataclass(frozen=True, slots=True)
class FillResult:
    path: Path
    written_bytes: int
    reason: str  # "cap" | "disk full" | "stopped"


def fill_logs(
    log_dir: Path, *, cap_bytes: int | None, stop: threading.Event | None = None
) -> FillResult:
    """Write junk into ``log_dir/fill.log`` until ``cap_bytes`` or the disk is full."""
    path = log_dir / "fill.log"
    chunk = (b"fill-logs: this robot writes until its log folder is full\n" * 20000)[:CHUNK_BYTES]
    written = 0
    reason = "stopped"
    with path.open("ab", buffering=0) as handle:
        while stop is None or not stop.is_set():
            size = len(chunk) if cap_bytes is None else min(len(chunk), cap_bytes - written)
            if size <= 0:
                reason = "cap"
                break
            try:
                written += handle.write(chunk[:size]) or 0
            except OSError as exc:
                if exc.errno not in (errno.ENOSPC, errno.EDQUOT, errno.EFBIG):
                    raise
                reason = "disk full"
                break
    logger.info("fill-logs stopped after %d bytes in %s: %s", written, path, reason)
    return FillResult(path, written, reason)


class MirrorFlooder:
    """Sends full datagrams to the team mirror as fast as the socket accepts them."""

    def __init__(self, mirror_ip: str, *, port: int = MIRROR_PORT) -> None:
        self._address = (mirror_ip, port)
        self._socket = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        self.sent_bytes = 0

    def run(self, stop: threading.Event) -> None:
        payload = os.urandom(DATAGRAM_BYTES)
        while not stop.is_set():
            try:
                self.sent_bytes += self._socket.sendto(payload, self._address)
            except OSError as exc:  # unreachable mirror, full buffer: keep trying
                logger.debug("mirror flood send failed: %s", exc)
                stop.wait(0.001)
        self._socket.close()
