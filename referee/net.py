"""GameController network: ``RGme`` to every robot on UDP 3838, ``RGrt`` from robots on 3939.

One background thread sends one packet to every robot address at a fixed rate (2 Hz; 20 Hz in a
game not paced to real time, :func:`contracts.send_period_s`) and never between, as the league
GameController's ``Sender`` does (a packet every 500 ms, every 50 ms with ``--fast``,
``packetNumber`` + 1 per packet, mod 256, stamped as it is sent). Each packet is the
latest state, except that a game state the robots have not been sent yet goes out first, at its
own tick: the league's referee waits until the GameController has broadcast a state (FINISHED
at the end of a half) before it commands the next one, so robots always see it; here FINISHED
lasts a single step before the next period's INITIAL. The thread also
receives return packets: per robot it tracks
the last alive time (wall clock), goalkeeper claims, manual penalise / unpenalise requests and
game-interruption-ready messages. Datagrams that do not decode are ignored and counted.

A return packet is attributed by its sender's address: when the robots' addresses are known, a
packet whose team number and player number name a robot other than the one at its source
address is a spoofing attempt; it changes nothing and is recorded in the shared
:class:`~referee.spoofing.SpoofingLog` with the sender.
"""

from __future__ import annotations

import logging
import selectors
import socket
import threading
import time
from collections.abc import Sequence
from dataclasses import dataclass, replace

from contracts import ReturnMessage, RobotId, TeamColor, decode_return, with_packet_number
from referee.clock import Clock
from referee.errors import ProtocolError
from referee.spoofing import Senders, SpoofingLog, robot_key

logger = logging.getLogger(__name__)

MAX_PENDING_STATES = 8  # game states waiting for their tick; older ones are dropped


@dataclass(slots=True)
class RobotLink:
    """What one robot told the GameController (times from the wall clock)."""

    address: str | None = None
    alive_s: float | None = None
    messages: int = 0
    goalkeeper_claim: bool = False
    manual_penalise: int = 0
    manual_unpenalise: int = 0
    ready_s: float | None = None


@dataclass(frozen=True, slots=True)
class NetworkStats:
    packets_sent: int
    datagrams_sent: int
    returns_received: int
    garbage: int
    unknown: int
    spoofed: int = 0


class GameControllerNetwork:
    def __init__(
        self,
        *,
        bind_host: str,
        data_port: int,
        return_port: int,
        targets: Sequence[str],
        team_numbers: dict[int, TeamColor],
        send_rate_hz: float,
        clock: Clock,
        senders: Senders | None = None,
        spoofing: SpoofingLog | None = None,
    ) -> None:
        self._senders = senders or Senders({})
        self._spoofing = spoofing or SpoofingLog()
        self._spoofed = 0
        self._targets = tuple(targets)
        self._data_port = data_port
        self._team_numbers = dict(team_numbers)
        self._period_s = 1.0 / send_rate_hz
        self._clock = clock
        self._lock = threading.Lock()
        self._packet: bytes | None = None
        self._pending: list[bytes] = []  # packets of game states not sent yet, oldest first
        self._packet_number = 0  # of the next packet (the league's Sender starts at 0)
        self._stop = threading.Event()
        self._links: dict[RobotId, RobotLink] = {}
        self._claims: list[RobotId] = []
        self._packets_sent = 0
        self._datagrams_sent = 0
        self._returns = 0
        self._garbage = 0
        self._unknown = 0
        self._send = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        self._send.bind((bind_host, 0))  # RGme leaves from the configured interface
        self._recv = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        self._recv.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        self._recv.bind((bind_host, return_port))
        self._recv.setblocking(False)
        self.return_address: tuple[str, int] = self._recv.getsockname()
        self._thread = threading.Thread(target=self._run, name="gamecontroller-net", daemon=True)

    def start(self) -> None:
        self._thread.start()

    def close(self) -> None:
        """Stop; a game state not sent yet (FINISHED at the end of the game) goes out first,
        as the league's GameController, still running, would broadcast it at its next tick."""
        self._stop.set()
        if self._thread.is_alive():
            self._thread.join(timeout=5.0)
        with self._lock:
            unsent, self._pending = self._pending, []
        for packet in unsent:
            self._send_packet(packet)
        self._send.close()
        self._recv.close()

    def __enter__(self) -> GameControllerNetwork:
        self.start()
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def publish(self, packet: bytes, *, state_changed: bool = False) -> None:
        """Make ``packet`` the latest state; nothing is sent before the next tick.
        ``state_changed``: it starts a new game state, which then is the packet of a tick even
        if the state is left again before."""
        with self._lock:
            self._packet = packet
            if state_changed:
                self._pending.append(packet)
                del self._pending[:-MAX_PENDING_STATES]

    def links(self) -> dict[RobotId, RobotLink]:
        with self._lock:
            return {robot: replace(link) for robot, link in self._links.items()}

    def take_goalkeeper_claims(self) -> list[RobotId]:
        with self._lock:
            claims, self._claims = self._claims, []
        return claims

    def stats(self) -> NetworkStats:
        with self._lock:
            return NetworkStats(
                self._packets_sent, self._datagrams_sent, self._returns, self._garbage,
                self._unknown, self._spoofed,
            )

    # --- thread ----------------------------------------------------------------------------

    def _run(self) -> None:
        """Send at the fixed rate on the machine's wall clock (the league's ``Sender`` sleeps
        500 ms between packets); the first packet goes out as soon as there is one."""
        selector = selectors.DefaultSelector()
        selector.register(self._recv, selectors.EVENT_READ)
        next_send = time.monotonic()
        try:
            while not self._stop.is_set():
                now = time.monotonic()
                if now >= next_send:
                    packet = self._next_packet()
                    if packet is not None:
                        self._send_packet(packet)
                        next_send += self._period_s
                        if next_send <= now:  # fell behind (a stalled machine): no burst
                            next_send = now + self._period_s
                timeout = max(0.0, min(0.02, next_send - time.monotonic()))
                if selector.select(timeout):
                    self._receive_all()
        finally:
            selector.close()

    def _next_packet(self) -> bytes | None:
        """The packet of this tick: a game state left before it was sent, else the latest."""
        with self._lock:
            if len(self._pending) > 1:  # the last pending one began the current state
                return self._pending.pop(0)
            self._pending.clear()
            return self._packet

    def _send_packet(self, packet: bytes) -> None:
        packet = with_packet_number(packet, self._packet_number)
        self._packet_number = (self._packet_number + 1) & 0xFF
        sent = 0
        for address in self._targets:
            try:
                self._send.sendto(packet, (address, self._data_port))
                sent += 1
            except OSError as exc:
                logger.debug("RGme to %s:%d failed: %s", address, self._data_port, exc)
        with self._lock:
            self._packets_sent += 1
            self._datagrams_sent += sent

    def _receive_all(self) -> None:
        while True:
            try:
                raw, (host, port) = self._recv.recvfrom(2048)
            except (BlockingIOError, InterruptedError):
                return
            except OSError as exc:
                logger.debug("RGrt receive failed: %s", exc)
                return
            self._handle(raw, f"{host}:{port}", host)

    def _handle(self, raw: bytes, peer: str, host: str) -> None:
        try:
            data = decode_return(raw, peer=peer)
        except ProtocolError as exc:
            with self._lock:
                self._garbage += 1
            logger.debug("ignored datagram: %s", exc)
            return
        color = self._team_numbers.get(data.team)
        claimed = RobotId(color, data.player) if color is not None else None
        if self._senders.known and (
            (claimed is None and not self._senders.robots_at(host))
            or (claimed is not None and not self._senders.may_speak_for(host, claimed))
        ):
            with self._lock:
                self._spoofed += 1
            self._spoofing.record(
                channel="gamecontroller", sender=host, sender_robot=self._senders.label(host),
                claimed=robot_key(claimed) if claimed is not None else f"team {data.team}",
                message=data.message.name,
            )
            return
        with self._lock:
            if color is None:
                self._unknown += 1
                return
            self._returns += 1
            robot = RobotId(color, data.player)
            link = self._links.setdefault(robot, RobotLink())
            now = self._clock.monotonic()
            link.address = host
            link.alive_s = now
            link.messages += 1
            if data.message is ReturnMessage.GOALKEEPER and not link.goalkeeper_claim:
                link.goalkeeper_claim = True
                self._claims.append(robot)
            elif data.message is ReturnMessage.MAN_PENALISE:
                link.manual_penalise += 1
            elif data.message is ReturnMessage.MAN_UNPENALISE:
                link.manual_unpenalise += 1
            elif data.message is ReturnMessage.GAME_INTERRUPTION_READY:
                link.ready_s = now
