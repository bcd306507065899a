"""The team mirror ("bouncing server") on UDP 3737.

Robots may not broadcast; a robot sends its team message to the mirror, which relays it to each
teammate (its IP, same port), never to the opponents. The sender is known by its source IP
among the team's hosts; unknown senders are ignored and counted, datagrams over 1024 bytes are
dropped whole (never truncated) and counted. An address listed for both teams is ignored. A
datagram from an address that is no member of either team is recorded as a spoofing attempt
(with its sender) in the shared :class:`~referee.spoofing.SpoofingLog`.
Log lines in the style of the league's ``bouncing_log.txt``.
"""

from __future__ import annotations

import logging
import selectors
import socket
import threading
import time
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TextIO

from contracts import TeamColor
from referee.spoofing import SpoofingLog

logger = logging.getLogger(__name__)

BOUNCING_LOG = "bouncing_log.txt"


@dataclass(frozen=True, slots=True)
class MirrorStats:
    forwarded: int  # datagrams relayed (one per teammate)
    received: int
    oversized: int
    unknown: int


class TeamMirror:
    def __init__(
        self,
        *,
        bind_host: str,
        port: int,
        teams: Mapping[TeamColor, Sequence[str]],
        max_bytes: int = 1024,
        log_dir: Path | None = None,
        spoofing: SpoofingLog | None = None,
    ) -> None:
        self._spoofing = spoofing or SpoofingLog()
        shared = set(teams.get(TeamColor.RED, ())) & set(teams.get(TeamColor.BLUE, ()))
        self._team_of: dict[str, TeamColor] = {}
        self._members: dict[TeamColor, tuple[str, ...]] = {}
        for color, hosts in teams.items():
            members = tuple(dict.fromkeys(h for h in hosts if h not in shared))
            self._members[color] = members
            for host in members:
                self._team_of[host] = color
        if shared:
            logger.warning("mirror ignores addresses listed for both teams: %s", sorted(shared))
        self._max_bytes = max_bytes
        self._lock = threading.Lock()
        self._forwarded = self._received = self._oversized = self._unknown = 0
        self._stop = threading.Event()
        self._socket = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        self._socket.bind((bind_host, port))
        self._socket.setblocking(False)
        self.address: tuple[str, int] = self._socket.getsockname()
        self._port = port if port else self.address[1]
        self._log: TextIO | None = None
        if log_dir is not None:
            log_dir.mkdir(parents=True, exist_ok=True)
            self._log = (log_dir / BOUNCING_LOG).open("w", encoding="utf-8")
        self._start_s = time.monotonic()
        self._thread = threading.Thread(target=self._run, name="team-mirror", daemon=True)

    def start(self) -> None:
        self._thread.start()

    def close(self) -> None:
        self._stop.set()
        if self._thread.is_alive():
            self._thread.join(timeout=5.0)
        self._socket.close()
        if self._log is not None:
            self._log.close()
            self._log = None

    def __enter__(self) -> TeamMirror:
        self.start()
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def stats(self) -> MirrorStats:
        with self._lock:
            return MirrorStats(self._forwarded, self._received, self._oversized, self._unknown)

    def _line(self, message: str) -> None:
        if self._log is not None:
            self._log.write(f"[{time.monotonic() - self._start_s:08.3f}] {message}\n")
            self._log.flush()

    def _run(self) -> None:
        selector = selectors.DefaultSelector()
        selector.register(self._socket, selectors.EVENT_READ)
        try:
            while not self._stop.is_set():
                if selector.select(0.05):
                    self._drain()
        finally:
            selector.close()

    def _drain(self) -> None:
        while True:
            try:
                payload, (host, port) = self._socket.recvfrom(65535)
            except (BlockingIOError, InterruptedError):
                return
            except OSError as exc:
                logger.debug("mirror receive failed: %s", exc)
                return
            self._relay(payload, host, port)

    def _relay(self, payload: bytes, host: str, port: int) -> None:
        team = self._team_of.get(host)
        with self._lock:
            self._received += 1
            if team is None:
                self._unknown += 1
            elif len(payload) > self._max_bytes:
                self._oversized += 1
        if team is None:
            self._line(f"Ignored {len(payload)} bytes from unknown host {host}:{port} (spoofing)")
            self._spoofing.record(channel="mirror", sender=host, sender_robot=None, claimed=None,
                                  message="team message")
            return
        if len(payload) > self._max_bytes:
            self._line(
                f"Dropped {len(payload)} bytes from {team.value} {host}: over {self._max_bytes}"
            )
            return
        sent = 0
        for mate in self._members[team]:
            if mate == host:
                continue
            try:
                self._socket.sendto(payload, (mate, self._port))
                sent += 1
            except OSError as exc:
                self._line(f"Failed to bounce to {mate}: {exc}")
        with self._lock:
            self._forwarded += sent
        self._line(f"Bounced {len(payload)} bytes from {team.value} {host} to {sent} teammates")
