"""The robots' ports: the sockets of the robot API server, multiplexed with ``selectors``.

:class:`Ports` listens on each robot's port, accepts and welcomes the team's clients (who may
speak as a robot is checked first, a name looked up off the step thread), refuses the others
(spoofing recorded), reads their requests and writes what is queued for them, pauses a client
whose budget is spent (:mod:`simulator.api.bounds`) and drops a client that failed. With the I/O
thread (:mod:`simulator.api.sender`) the connections' reads and writes are there: the step
thread's selector only accepts, takes camera results and, in lockstep, the I/O thread's
wake-ups. ``connection_changes`` counts the clients welcomed or dropped: the other pieces of the
server compare it to know that nobody came or left.
"""

from __future__ import annotations

import logging
import os
import selectors
import socket
import threading
import time
from collections.abc import Callable, Mapping
from concurrent.futures import ThreadPoolExecutor

from contracts import NetworkSpec, RobotId
from referee import SpoofingLog
from simulator.api.connection import AnswerBook, ClientClosed, Connection
from simulator.api.devices import DeviceWorld
from simulator.api.endpoints import peer_allowed_by_name
from simulator.api.exchange import Exchange, settle
from simulator.api.framing import REFUSED, WELCOME
from simulator.api.sender import SendThread
from simulator.api.slots import LockstepSettings, PortUnavailable, RobotSlot

log = logging.getLogger(__name__)

# while a client is paused for its budget (simulator.api.bounds), the longest a poll sleeps
PAUSED_POLL_S = 0.002


class Ports:
    """The clients' sockets of every robot's slot. :meth:`start` listens, :meth:`close` closes
    everything; :meth:`poll` serves the sockets on the step thread."""

    def __init__(
        self,
        *,
        world: DeviceWorld,
        slots: Mapping[RobotId, RobotSlot],
        network: NetworkSpec,
        lockstep: LockstepSettings | None,
        spoofing: SpoofingLog,
        send_thread: bool,
        send_cpus: frozenset[int] | None,
        exchange: bool = False,
    ) -> None:
        """``exchange``: plain lockstep's steady steps exchanged by a compiled thread
        (:mod:`simulator.api.exchange`; on ``send_cpus`` when given), where it can run."""
        self._world = world
        self._slots = slots
        self._network = network
        self._lockstep = lockstep
        self._spoofing = spoofing
        self._use_sender = send_thread
        self._send_cpus = send_cpus
        self._selector = selectors.DefaultSelector()
        self._lookups: ThreadPoolExecutor | None = None
        # the I/O thread, while started with one
        self.sender: SendThread | None = None
        self._use_exchange = exchange
        # plain lockstep's exchange thread, while started with one
        self.exchange: Exchange | None = None
        # lockstep: who owes an answer and who is slow, kept as it changes (one look per wait)
        self.answers: AnswerBook | None = AnswerBook() if lockstep is not None else None
        self.stop_requested = False
        # lockstep with the I/O thread: the step thread waiting for answers is woken through
        # this pipe, written by the I/O thread only while ``awaiting_answers`` is set
        self.awaiting_answers = False
        self._wake: tuple[int, int] | None = None
        self._wake_sent = False
        # set when a measurement starts waiting for images or a client for its name lookup (the
        # step thread polls every step until none waits)
        self.maybe_waiting = False
        # step-thread clients whose budget is spent (simulator.api.bounds), not read for now
        self._paused: list[RobotSlot] = []
        self.connection_changes = 0  # clients welcomed or dropped so far
        # the lock of every connection's requests (and, with the I/O thread, its board slot)
        self.requests_lock = threading.Lock()

    def add_reader(self, fd: int, ready: Callable[[], None]) -> None:
        """Call ``ready`` from :meth:`poll` when ``fd`` is readable."""
        self._selector.register(fd, selectors.EVENT_READ, ready)

    # --- lifecycle --------------------------------------------------------------------------

    def start(self) -> None:
        if self._use_sender and self.sender is None:
            if self._lockstep is not None:
                self._wake = os.pipe()
                for fd in self._wake:
                    os.set_blocking(fd, False)
                self.add_reader(self._wake[0], self._drain_wake)
            self.sender = SendThread(cpus=self._send_cpus, on_news=self._news, poll=True)
        if self._use_exchange and self.exchange is None and self.sender is None:
            self.exchange = Exchange.start(self._send_cpus)
        host = self._network.api_bind_host
        for slot in self._slots.values():
            sock = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
            sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
            try:
                sock.bind((host, slot.endpoint.port))
                sock.listen(4)
            except OSError as exc:
                sock.close()
                self.close()
                raise PortUnavailable(host=host, port=slot.endpoint.port, reason=str(exc)) from exc
            sock.setblocking(False)
            slot.listener = sock
            self._selector.register(sock, selectors.EVENT_READ, ("accept", slot))
            log.info(
                "robot API for %s listening on %s:%d", slot.session.key, host, slot.endpoint.port
            )

    def close(self) -> None:
        self.count_owed()
        if self.exchange is not None:
            self.exchange.close()
            self.exchange = None
        for slot in self._slots.values():
            if slot.conn is not None:
                self.drop(slot, "server shutting down")
            if slot.checking is not None:
                slot.checking[0].close()
                slot.checking = None
            if slot.listener is not None:
                self._selector.unregister(slot.listener)
                slot.listener.close()
                slot.listener = None
        if self._lookups is not None:
            self._lookups.shutdown(wait=False, cancel_futures=True)
        if self.sender is not None:
            self.sender.close()
            self.sender = None
        self._selector.close()
        if self._wake is not None:
            for fd in self._wake:
                os.close(fd)
            self._wake = None

    # --- serving ----------------------------------------------------------------------------

    def poll(self, timeout_s: float = 0.0) -> None:
        """Serve sockets: accept, handshake, read requests, write queued measurements (with
        the I/O thread: drop the clients it found failed); call the readers whose descriptor
        is ready (:meth:`add_reader`)."""
        self.count_owed()
        if self._paused and timeout_s > PAUSED_POLL_S:
            timeout_s = PAUSED_POLL_S  # a paused client is read again soon after it refills
        ready = self._selector.select(max(0.0, timeout_s))
        # after the select: a request that arrives while it blocks is stamped when it arrived
        # (its round trip and its lockstep answer time), not when the wait began
        now = time.monotonic()
        for key, events in ready:
            data = key.data
            if callable(data):
                data()
                continue
            kind, slot = data
            if kind == "accept":
                self._accept(slot)
            elif slot.conn is not None and key.fileobj is slot.conn.sock:
                if events & selectors.EVENT_READ:
                    self.read(slot, now)
                if slot.conn is not None and events & selectors.EVENT_WRITE:
                    self.flush(slot)
        if self._paused:
            self._resume_paused(now)
        if self._lookups is not None:
            self._finish_lookups()
        if self.sender is not None:
            for slot in self._slots.values():
                conn = slot.conn
                if conn is not None and conn.error is not None:
                    self.drop(slot, conn.error)

    def settle(self, wait_s: float) -> None:
        """End the exchange in flight, if any (:func:`simulator.api.exchange.settle`): its
        thread reads answers for ``wait_s`` at most, what it did not take is read here. The
        counting of an exchange that took every answer may wait (:meth:`count_owed`)."""
        exchange = self.exchange
        if exchange is not None and exchange.run is not None:
            settle(exchange, self, wait_s)

    def count_owed(self) -> None:
        """End the exchange in flight and count everything it sent and read: the connections'
        state and statistics are whole after it."""
        self.settle(0.0)
        if self.exchange is not None:
            self.exchange.count_owed()

    def _news(self) -> None:
        """I/O thread: requests arrived or a client failed; wake a waiting step thread."""
        if self.awaiting_answers and not self._wake_sent and self._wake is not None:
            self._wake_sent = True
            try:
                os.write(self._wake[1], b"\0")
            except (BlockingIOError, OSError):
                pass  # full (a wake-up is pending anyway) or closed (shutting down)

    def _drain_wake(self) -> None:
        assert self._wake is not None
        try:
            os.read(self._wake[0], 4096)
        except BlockingIOError:
            pass
        self._wake_sent = False  # cleared after reading: a later wake-up is not lost

    # --- who may connect --------------------------------------------------------------------

    def _accept(self, slot: RobotSlot) -> None:
        assert slot.listener is not None
        while True:
            try:
                sock, address = slot.listener.accept()
            except (BlockingIOError, InterruptedError):
                return
            except OSError as exc:
                log.warning("%s: accept failed: %s", slot.session.key, exc)
                return
            peer = f"{address[0]}:{address[1]}"
            ip = address[0]
            if ip in slot.endpoint.others or (
                ip not in slot.endpoint.allowed_ips and not slot.endpoint.allowed_names
            ):  # who may speak as this robot is checked first, connected or not
                self._refuse_host(slot, sock, peer)
                continue
            if slot.conn is not None or slot.checking is not None:
                slot.stats.refused += 1
                log.warning(
                    "%s: refused %s: a client is already connected on port %d",
                    slot.session.key, peer, slot.endpoint.port,
                )  # fmt: skip
                _refuse(sock)
                continue
            if ip in slot.endpoint.allowed_ips:
                self._welcome(slot, sock, peer)
                continue
            if self._lookups is None:  # the team's hosts are names: resolve off the step thread
                self._lookups = ThreadPoolExecutor(max_workers=1, thread_name_prefix="api-dns")
            names = sorted(slot.endpoint.allowed_names)
            future = self._lookups.submit(peer_allowed_by_name, ip, names)
            slot.checking = (sock, peer, future)
            self.maybe_waiting = True

    def _finish_lookups(self) -> None:
        for slot in self._slots.values():
            if slot.checking is None or not slot.checking[2].done():
                continue
            sock, peer, future = slot.checking
            slot.checking = None
            if future.result():
                self._welcome(slot, sock, peer)
            else:
                self._refuse_host(slot, sock, peer)

    def _refuse_host(self, slot: RobotSlot, sock: socket.socket, peer: str) -> None:
        slot.stats.refused += 1
        ip = peer.rpartition(":")[0]
        other = slot.endpoint.others.get(ip)
        if other is not None:
            log.warning("%s: refused %s: the address of %s (spoofing)", slot.session.key, peer,
                        other)
        else:
            log.warning(
                "%s: refused %s: not in the team's hosts %s",
                slot.session.key, peer, list(slot.endpoint.hosts),
            )  # fmt: skip
        self._spoofing.record(channel="api", sender=ip, sender_robot=other,
                              claimed=slot.endpoint.key, message="connect")
        _refuse(sock)

    def _welcome(self, slot: RobotSlot, sock: socket.socket, peer: str) -> None:
        try:
            sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
            sock.sendall(WELCOME)
        except OSError as exc:
            log.warning("%s: handshake with %s failed: %s", slot.session.key, peer, exc)
            sock.close()
            return
        sock.setblocking(False)
        bank = self._lockstep.time_bank_s if self._lockstep else 0.0
        slot.conn = Connection(
            sock=sock,
            peer=peer,
            key=slot.session.key,
            stats=slot.stats,
            queue_limit=self._network.send_queue_messages,
            time_bank_s=bank,
            threaded=self.sender is not None,
            requests_lock=self.requests_lock,
        )
        if self.answers is not None:
            slot.conn.book = self.answers
            slot.conn.owe()  # a new client owes its first request
        slot.pending.clear()
        slot.stats.connects.append(time.time())
        self.connection_changes += 1
        if self.sender is not None:
            slot.mask = 0  # the I/O thread watches it
            self.sender.add(slot.conn)
        else:
            slot.mask = selectors.EVENT_READ
            self._selector.register(sock, slot.mask, ("conn", slot))
        log.info(
            "%s: client %s connected on port %d (sim time %d ms)",
            slot.session.key, peer, slot.endpoint.port, self._world.sim_time_ms,
        )  # fmt: skip

    # --- a client's socket ------------------------------------------------------------------

    def read(self, slot: RobotSlot, now: float) -> None:
        """Read the slot's client now, dropping it when it failed (also when its socket does
        not say it is readable: bytes handed back to it, :attr:`Connection.preread`)."""
        conn = slot.conn
        assert conn is not None
        try:
            conn.read(now)
        except ClientClosed as exc:
            self.drop(slot, exc.reason)
            return
        if conn.paused:  # its budget is spent: its socket is not watched until it refills
            self._paused.append(slot)
            self._watch(slot, conn)

    def _resume_paused(self, now: float) -> None:
        """Read again the paused clients whose budget refilled (:mod:`simulator.api.bounds`)."""
        paused, self._paused = self._paused, []
        for slot in paused:
            conn = slot.conn
            if conn is None or not conn.paused:
                continue  # dropped, or a new client since
            if not conn.resume(now):
                self._paused.append(slot)
                continue
            self._watch(slot, conn)
            self.read(slot, now)  # frames may be buffered: the socket would not say so

    def flush(self, slot: RobotSlot) -> None:
        """Write what the client's socket takes of its queue (step thread)."""
        conn = slot.conn
        assert conn is not None
        try:
            conn.flush()
        except ClientClosed as exc:
            self.drop(slot, exc.reason)
            return
        self._watch(slot, conn)

    def flush_blocking(self, slot: RobotSlot) -> None:
        """HLVS behaviour: wait until the client has taken everything (stalls the step)."""
        while slot.conn is not None and not slot.conn.idle and not self.stop_requested:
            conn = slot.conn
            with selectors.DefaultSelector() as one:
                one.register(conn.sock, selectors.EVENT_WRITE)
                one.select(0.1)
            self.flush(slot)

    def _watch(self, slot: RobotSlot, conn: Connection) -> None:
        """Watch the client's socket for what it needs: reading unless paused, writing while
        frames wait (a socket with neither is not registered)."""
        mask = (0 if conn.paused else selectors.EVENT_READ) | (
            selectors.EVENT_WRITE if conn.want_write else 0
        )
        old = slot.mask
        if mask == old:
            return
        slot.mask = mask
        if not old:
            self._selector.register(conn.sock, mask, ("conn", slot))
        elif not mask:
            self._selector.unregister(conn.sock)
        else:
            self._selector.modify(conn.sock, mask, ("conn", slot))

    def drop(self, slot: RobotSlot, reason: str) -> None:
        """Close the slot's client (if any), counted and logged with ``reason``."""
        conn = slot.conn
        if conn is None:
            return
        self.count_owed()  # the exchange thread may be writing to its socket
        # the statistics first: whoever sees the client gone also sees why
        slot.stats.disconnects.append(time.time())
        slot.stats.disconnect_reasons.append(reason)
        slot.conn = None
        slot.pending.clear()
        if self.answers is not None:
            self.answers.forget(conn)
        self.connection_changes += 1
        if conn.threaded and self.sender is not None:
            self.sender.remove(conn)
        else:
            try:
                self._selector.unregister(conn.sock)
            except (KeyError, ValueError):
                pass  # never registered or selector closed
        conn.close()
        log.info("%s: client %s dropped: %s", slot.session.key, conn.peer, reason)


def _refuse(sock: socket.socket) -> None:
    try:
        sock.setblocking(False)
        sock.send(REFUSED)
    except OSError:
        pass  # the peer is gone already; nothing to tell it
    finally:
        sock.close()
