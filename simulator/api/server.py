"""The robot API server: one TCP port per robot, multiplexed with ``selectors``.

All socket I/O is non-blocking and runs on the step thread at three points of each step
(:meth:`ApiServer.poll` while waiting or pacing, :meth:`ApiServer.apply_requests` before the
physics step, :meth:`ApiServer.publish` after it), so the world is only touched by one thread and
a client can never block the step (except with ``blocking_send``, the HLVS behaviour). In async
stepping the clients' reads and writes go to an I/O thread (:mod:`simulator.api.sender`): the
step thread reads the step's sensor values, hands the measurements over (framed and queued
there), takes decoded requests and goes back to the physics.

Per step: every complete request received is applied (later ones override earlier targets),
then one ``SensorMeasurements`` per connected robot is queued. Lockstep: :meth:`wait_lockstep`
waits for one request per connected, non-slow client (see :mod:`simulator.api.lockstep`).
Pipelined lockstep takes the answers with :meth:`take_requests` before the measurement of the
step just computed is sent and applies them with :meth:`apply_taken` (see
:mod:`simulator.match_loop`).
"""

from __future__ import annotations

import logging
import os
import selectors
import socket
import threading
import time
from collections import deque
from collections.abc import Callable, Sequence
from concurrent.futures import Future, ThreadPoolExecutor
from dataclasses import dataclass, field
from functools import partial

import numpy as np
import numpy.typing as npt

from contracts import NetworkSpec, RobotApiStats, RobotId
from contracts.robot_api import messages_pb2 as pb
from referee import SpoofingLog
from simulator.api.batch import Encoding, Gathered, StepBatch
from simulator.api.board import TargetBoard
from simulator.api.cameras import MAX_IN_FLIGHT, ImageSource
from simulator.api.connection import AnswerBook, ClientClosed, Connection
from simulator.api.devices import DeviceWorld
from simulator.api.endpoints import PlayerEndpoint, peer_allowed_by_name
from simulator.api.fastreq import Notice, PositionTargets, TargetValues
from simulator.api.framing import HEADER, REFUSED, WELCOME
from simulator.api.quota import NetworkQuota
from simulator.api.sender import SendThread
from simulator.api.session import (
    ERROR,
    WARNING,
    DuePlan,
    Measurement,
    RobotSession,
    SteadyChanges,
    TargetPlan,
    header_bytes,
)
from simulator.api.stats import RobotStats
from simulator.errors import ApiError

log = logging.getLogger(__name__)

Request = pb.ActuatorRequests | PositionTargets | Notice

# With the I/O thread the step thread's own selector only accepts connections (and takes camera
# images): before a step it is polled when POLL_INTERVAL_S of wall time has passed since the last
# poll, and every step while a measurement waits for an image or a name lookup runs. A world that
# steps faster than real time makes no syscall on most steps (a select between two physics steps
# costs the step thread the select and the memory it touches); a client is still welcomed within
# that interval.
POLL_INTERVAL_S = 0.01
# while a client is paused for its budget (simulator.api.bounds), the longest a poll sleeps
PAUSED_POLL_S = 0.002


class IoThreadFailed(ApiError):
    """The thread doing the clients' socket I/O stopped on an unexpected error."""

    def __init__(self, failure: Exception) -> None:
        self.failure = failure
        super().__init__(
            f"the robot API I/O thread failed ({failure!r}): no robot would receive"
            " measurements any more, so the match stops here"
        )


class PortUnavailable(ApiError):
    def __init__(self, *, host: str, port: int, reason: str) -> None:
        self.host = host
        self.port = port
        self.reason = reason
        super().__init__(f"cannot listen on {host}:{port}: {reason}")


@dataclass(slots=True)
class _Pending:
    """A measurement waiting for camera images (and the ones queued behind it)."""

    measurement: Measurement
    missing: int


@dataclass(frozen=True, slots=True)
class _SteadyStep:
    """The connected robots of a step whose every measurement was a steady session's
    (:attr:`RobotSession.steady`), all due at the same steps (one period, starts that differ by
    whole periods: robots that enabled their sensors at different steps). While no client
    connects or leaves, no robot is removed and no session's steady state changes,
    :meth:`ApiServer.prepare` builds a step due by it without asking each session: one gather
    of ``plans``, one plain measurement per robot, what the sessions would give."""

    connection_changes: int
    steady_changes: int
    slots: tuple[RobotSlot, ...]
    conns: tuple[Connection, ...]
    plans: tuple[DuePlan, ...]
    period: int
    phase: int  # due when the step's time modulo ``period`` is ``phase``
    # the encoding of ``plans`` the step was recorded with: its gather reads every step's
    # values; a head of another size (a time with more varint bytes) takes another encoding
    encoding: Encoding

    def encoding_for(self, batch: StepBatch, head: bytes) -> Encoding:
        """The encoding of ``plans`` with room for ``head``."""
        if self.encoding.head_size == len(head):
            return self.encoding
        return batch.encoding(self.plans, len(head))


@dataclass(slots=True)
class _SteadyValues:
    """One step's sensor values gathered by a :class:`_SteadyStep`, not yet wire bytes (the
    head of the step's time is written with them, on the I/O thread)."""

    step: _SteadyStep
    values: npt.NDArray[np.float64]
    time_ms: int
    real_time: int

    def frames(self, batch: StepBatch) -> list[bytes]:
        """Every robot's framed plain measurement of the step."""
        head = header_bytes(self.time_ms, self.real_time)
        return self.step.encoding_for(batch, head).frames(self.values, head)

    def measurements(self, batch: StepBatch) -> list[tuple[RobotSlot, Measurement]]:
        """The step's measurements robot by robot, written (as :meth:`ApiServer.prepare`
        makes them without the steady form)."""
        measurements = [Measurement(self.time_ms, self.real_time) for _ in self.step.slots]
        head = header_bytes(self.time_ms, self.real_time)
        self.step.encoding_for(batch, head).write(self.values, head, measurements)
        return list(zip(self.step.slots, measurements, strict=True))


@dataclass(slots=True)
class Prepared:
    """The measurements of one step (:meth:`ApiServer.prepare`) and, with the I/O thread,
    their sensor values read but not yet written as wire bytes (``unwritten``: the I/O thread
    writes them before it queues the frames); or, in a steady step, the values alone
    (``steady``: the I/O thread frames them for every robot)."""

    items: list[tuple[RobotSlot, Measurement]]
    unwritten: Gathered | None = None
    steady: _SteadyValues | None = None


@dataclass(slots=True, eq=False)
class RobotSlot:
    endpoint: PlayerEndpoint
    session: RobotSession
    quota: NetworkQuota
    stats: RobotStats
    listener: socket.socket | None = None
    conn: Connection | None = None
    checking: tuple[socket.socket, str, Future[bool]] | None = None
    pending: deque[_Pending] = field(default_factory=deque)
    mask: int = 0


@dataclass(frozen=True, slots=True, kw_only=True)
class LockstepSettings:
    deadline_s: float
    time_bank_s: float
    # pipelined lockstep: the clients' socket I/O runs on the I/O thread, while the physics
    # runs; plain lockstep keeps it on the step thread (fewer wake-ups in the critical path)
    pipelined: bool = False


class ApiServer:
    """Robot API server of a match. Use as a context manager (closes every socket)."""

    def __init__(
        self,
        *,
        world: DeviceWorld,
        endpoints: Sequence[PlayerEndpoint],
        network: NetworkSpec,
        lockstep: LockstepSettings | None = None,
        cameras: ImageSource | None = None,
        unix_ms: Callable[[], int] = lambda: int(time.time() * 1000),
        send_thread: bool | None = None,
        send_cpus: frozenset[int] | None = None,
        spoofing: SpoofingLog | None = None,
    ) -> None:
        """``send_thread``: the clients' reads and writes on an I/O thread (default: in async
        and pipelined stepping without ``blocking_send``); ``send_cpus``: the CPUs that thread
        may use."""
        self._world = world
        # the per-step work over all robots at once, when the world has the batch forms
        self._batch = StepBatch(world) if StepBatch.supports(world) else None
        self._spoofing = spoofing or SpoofingLog()
        self._network = network
        self._lockstep = lockstep
        # lockstep: who owes an answer and who is slow, kept as it changes (one look per wait)
        self.answers: AnswerBook | None = AnswerBook() if lockstep is not None else None
        self._cameras = cameras
        self._unix_ms = unix_ms
        self._selector = selectors.DefaultSelector()
        self._lookups: ThreadPoolExecutor | None = None
        self.stop_requested = False
        if send_thread is None:
            send_thread = not network.blocking_send and (lockstep is None or lockstep.pipelined)
        self._send_cpus = send_cpus
        self._sender: SendThread | None = None
        self._use_sender = send_thread
        # lockstep with the I/O thread: the step thread waiting for answers is woken through
        # this pipe, written by the I/O thread only while ``awaiting_answers`` is set
        self.awaiting_answers = False
        self._wake: tuple[int, int] | None = None
        self._wake_sent = False
        self._next_poll = 0.0  # with the I/O thread: when the step thread polls its selector next
        # set when a measurement starts waiting for images or a client for its name lookup (the
        # step thread polls every step until none waits: :meth:`_waiting`)
        self._maybe_waiting = False
        # step-thread clients whose budget is spent (simulator.api.bounds), not read for now
        self._paused: list[RobotSlot] = []
        self.connection_changes = 0  # clients welcomed or dropped so far
        # with the I/O thread: this step's measurements to frame and queue there, in order
        self._outgoing: list[tuple[RobotSlot, Connection, Measurement]] = []
        self._unwritten: Gathered | None = None
        self._sent_at = 0.0
        self._hold_told: set[tuple[int, int]] = set()  # (connection id, held sim time) told
        # the steady form of the last step built robot by robot (None: not every robot steady)
        self._steady_step: _SteadyStep | None = None
        # the world's removed flags (changed in place), when it has them: a removed robot's
        # measurement is not its steady one
        flags = getattr(world, "robot_flags", None)
        world_flags = flags(endpoints[0].robot) if flags is not None and endpoints else None
        self._removed_flags: list[bool] | None = world_flags[1] if world_flags else None
        # the world's limp flags (changed in place) and a copy as the sessions last saw them
        self._limp_flags: list[bool] | None = world_flags[0] if world_flags else None
        self._limp_seen: list[bool] | None = None
        # with the I/O thread: every robot's usual targets in one array (simulator.api.board),
        # and the lock of every connection's requests and board slot
        self._board: TargetBoard | None = None
        self._requests_lock = threading.Lock()
        self.slots: dict[RobotId, RobotSlot] = {}
        self._steady_changes = SteadyChanges()
        for endpoint in endpoints:
            team_size = max(1, endpoint.team_size)
            session = RobotSession(
                robot=endpoint.robot,
                world=world,
                rendering_quota_mb_s=network.rendering_quota_mb_s / team_size,
                clock_ms=unix_ms,
                steady_changes=self._steady_changes,
            )
            self.slots[endpoint.robot] = RobotSlot(
                endpoint=endpoint,
                session=session,
                quota=NetworkQuota(quota_mb_s=network.team_quota_mb_s / team_size),
                stats=RobotStats(),
            )
        if cameras is not None:
            self._selector.register(cameras.wake_fd, selectors.EVENT_READ, "cameras")

    # --- lifecycle --------------------------------------------------------------------------

    def start(self) -> None:
        if self._use_sender and self._sender is None:
            if self._lockstep is not None:
                self._wake = os.pipe()
                for fd in self._wake:
                    os.set_blocking(fd, False)
                self._selector.register(self._wake[0], selectors.EVENT_READ, "wake")
            self._sender = SendThread(
                cpus=self._send_cpus, on_news=self._news, poll=True
            )
        host = self._network.api_bind_host
        for slot in self.slots.values():
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
        for slot in self.slots.values():
            if slot.conn is not None:
                self._drop(slot, "server shutting down")
            if slot.checking is not None:
                slot.checking[0].close()
                slot.checking = None
            if slot.listener is not None:
                self._selector.unregister(slot.listener)
                slot.listener.close()
                slot.listener = None
        if self._lookups is not None:
            self._lookups.shutdown(wait=False, cancel_futures=True)
        if self._sender is not None:
            self._sender.close()
            self._sender = None
        self._selector.close()
        if self._wake is not None:
            for fd in self._wake:
                os.close(fd)
            self._wake = None

    def __enter__(self) -> ApiServer:
        self.start()
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    # --- queries ----------------------------------------------------------------------------

    def connected(self) -> list[str]:
        return [slot.session.key for slot in self.slots.values() if slot.conn is not None]

    def traffic(self) -> dict[str, tuple[bool, RobotStats]]:
        """Each robot's live counters and whether it is connected (cheap: nothing copied)."""
        return {s.session.key: (s.conn is not None, s.stats) for s in self.slots.values()}

    def statistics(self) -> dict[str, RobotApiStats]:
        return {slot.session.key: slot.stats.to_dict() for slot in self.slots.values()}

    @property
    def io_wakes(self) -> int:
        """Wake-ups of the I/O thread the step thread has paid for so far (a write to its pipe
        each: :mod:`simulator.api.sender`); 0 without the thread."""
        return self._sender.wakes if self._sender is not None else 0

    def connection(self, robot: RobotId) -> Connection | None:
        return self.slots[robot].conn

    # --- I/O --------------------------------------------------------------------------------

    def poll(self, timeout_s: float = 0.0) -> None:
        """Serve sockets: accept, handshake, read requests, write queued measurements (with
        the I/O thread: drop the clients it found failed)."""
        if self._paused and timeout_s > PAUSED_POLL_S:
            timeout_s = PAUSED_POLL_S  # a paused client is read again soon after it refills
        ready = self._selector.select(max(0.0, timeout_s))
        # after the select: a request that arrives while it blocks is stamped when it arrived
        # (its round trip and its lockstep answer time), not when the wait began
        now = time.monotonic()
        for key, events in ready:
            data = key.data
            if data == "cameras":
                self._camera_results()
                continue
            if data == "wake":
                self._drain_wake()
                continue
            kind, slot = data
            if kind == "accept":
                self._accept(slot)
            elif slot.conn is not None and key.fileobj is slot.conn.sock:
                if events & selectors.EVENT_READ:
                    self._read(slot, now)
                if slot.conn is not None and events & selectors.EVENT_WRITE:
                    self._flush(slot)
        if self._paused:
            self._resume_paused(now)
        if self._lookups is not None:
            self._finish_lookups()
        if self._sender is not None:
            for slot in self.slots.values():
                conn = slot.conn
                if conn is not None and conn.error is not None:
                    self._drop(slot, conn.error)

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
            self._maybe_waiting = True

    def _finish_lookups(self) -> None:
        for slot in self.slots.values():
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
            threaded=self._sender is not None,
            requests_lock=self._requests_lock,
        )
        if self.answers is not None:
            slot.conn.book = self.answers
            slot.conn.owe()  # a new client owes its first request
        slot.pending.clear()
        slot.stats.connects.append(time.time())
        self.connection_changes += 1
        if self._sender is not None:
            slot.mask = 0  # the I/O thread watches it
            self._sender.add(slot.conn)
        else:
            slot.mask = selectors.EVENT_READ
            self._selector.register(sock, slot.mask, ("conn", slot))
        log.info(
            "%s: client %s connected on port %d (sim time %d ms)",
            slot.session.key, peer, slot.endpoint.port, self._world.sim_time_ms,
        )  # fmt: skip

    def _read(self, slot: RobotSlot, now: float) -> None:
        conn = slot.conn
        assert conn is not None
        try:
            conn.read(now)
        except ClientClosed as exc:
            self._drop(slot, exc.reason)
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
            self._read(slot, now)  # frames may be buffered: the socket would not say so

    def _flush(self, slot: RobotSlot) -> None:
        conn = slot.conn
        assert conn is not None
        try:
            conn.flush()
        except ClientClosed as exc:
            self._drop(slot, exc.reason)
            return
        self._watch(slot, conn)

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

    def _drop(self, slot: RobotSlot, reason: str) -> None:
        conn = slot.conn
        if conn is None:
            return
        # the statistics first: whoever sees the client gone also sees why
        slot.stats.disconnects.append(time.time())
        slot.stats.disconnect_reasons.append(reason)
        slot.conn = None
        slot.pending.clear()
        if self.answers is not None:
            self.answers.forget(conn)
        self.connection_changes += 1
        if conn.threaded and self._sender is not None:
            self._sender.remove(conn)
        else:
            try:
                self._selector.unregister(conn.sock)
            except (KeyError, ValueError):
                pass  # never registered or selector closed
        conn.close()
        log.info("%s: client %s dropped: %s", slot.session.key, conn.peer, reason)

    # --- the step ---------------------------------------------------------------------------

    def _poll_before_step(self) -> None:
        if self._sender is not None:
            now = time.monotonic()
            if now < self._next_poll and not (self._maybe_waiting and self._waiting()):
                return
            self._next_poll = now + POLL_INTERVAL_S
        self.poll(0.0)

    def _waiting(self) -> bool:
        """Some measurement waits for a camera image, or some client for its name lookup (then
        the step thread polls every step); clears ``_maybe_waiting`` when none does."""
        if any(slot.pending or slot.checking for slot in self.slots.values()):
            return True
        self._maybe_waiting = False
        return False

    def apply_requests(self, step_time_ms: int) -> None:
        """Read what is available, then apply every received request in arrival order.
        While the target board is armed that is one write of what the I/O thread posted on it
        (:mod:`simulator.api.board`); a step that applies the usual request of every connected
        robot arms it."""
        self._poll_before_step()
        board = self._board
        if board is not None:
            if self._board_holds(board) and board.apply(self._requests_lock):
                return
            self._end_board()
        self._update_limps()
        received: list[tuple[RobotSession, list[Request]]] = []
        connections: list[Connection] = []
        for slot in self.slots.values():
            session = slot.session
            conn = slot.conn
            if conn is None:
                continue
            connections.append(conn)
            if conn.threaded:
                if conn.error is not None:  # found by the I/O thread
                    self._drop(slot, conn.error)
                    continue
                if conn.requests:
                    received.append((session, conn.take_requests()))
            elif conn.requests:
                received.append((session, conn.requests))
                conn.requests = []
        usual = self._apply(received, step_time_ms)
        if usual and len(usual) == len(connections) and self._limp_flags is not None:
            self._arm_board(connections, [session for session, _ in received], usual)

    def _board_holds(self, board: TargetBoard) -> bool:
        """Nothing that ends the target board happened since it was armed: the same clients,
        none failed, no robot made limp, released or removed (the requests it queued are
        counted by :meth:`TargetBoard.apply`)."""
        if board.connection_changes != self.connection_changes:
            return False
        if self._limp_flags != self._limp_seen:
            return False
        if self._removed_flags != board.removed:
            return False
        for conn in board.conns:
            if conn.error is not None:
                return False
        return True

    def _arm_board(
        self,
        connections: list[Connection],
        sessions: list[RobotSession],
        usual: list[tuple[TargetPlan, TargetValues]],
    ) -> None:
        """Arm the target board after a step that wrote every connected robot's usual
        targets (with the I/O thread and the world's limp and removed flags)."""
        if self._sender is None or self._batch is None or self._removed_flags is None:
            return
        board = TargetBoard(
            [(conn, session, plan, values)
             for conn, session, (plan, values) in zip(connections, sessions, usual, strict=True)],
            self._batch,
            connection_changes=self.connection_changes,
            removed=list(self._removed_flags),
        )  # fmt: skip
        if board.attach(self._requests_lock):
            self._board = board

    def _end_board(self) -> None:
        """End the target board, if armed: the robot-by-robot path goes on from what it
        held (:meth:`TargetBoard.end`)."""
        board = self._board
        if board is not None:
            self._board = None
            board.end(self._requests_lock)

    def _update_limps(self) -> None:
        """Every session follows the world's limp flags (:meth:`RobotSession.update_limp`);
        one comparison with the flags seen last when the world has them in a list."""
        limp = self._limp_flags
        if limp is not None and limp == self._limp_seen:
            return
        for slot in self.slots.values():
            slot.session.update_limp()
        if limp is not None:
            self._limp_seen = list(limp)

    def take_requests(self) -> dict[RobotId, list[Request]]:
        """Pipelined stepping: read what is available and detach every client's received
        requests, to be applied later by :meth:`apply_taken` (the step after next)."""
        self._poll_before_step()
        self._end_board()
        taken: dict[RobotId, list[Request]] = {}
        for robot, slot in self.slots.items():
            conn = slot.conn
            if conn is None:
                continue
            if conn.threaded and conn.error is not None:  # found by the I/O thread
                self._drop(slot, conn.error)
                continue
            if conn.requests:
                taken[robot] = conn.take_requests()
        return taken

    def apply_taken(self, taken: dict[RobotId, list[Request]], step_time_ms: int) -> None:
        """Pipelined stepping: apply requests detached by :meth:`take_requests` in arrival
        order (a robot's requests apply even when its client left since)."""
        self._end_board()
        self._update_limps()
        slots = self.slots
        self._apply(
            [(slots[robot].session, requests) for robot, requests in taken.items() if requests],
            step_time_ms,
        )

    def _apply(
        self, received: list[tuple[RobotSession, list[Request]]], step_time_ms: int
    ) -> list[tuple[TargetPlan, TargetValues]] | None:
        """Apply each robot's requests (after its :meth:`RobotSession.update_limp`): the usual
        ones of every robot in one batched write, the others robot by robot. The batched
        robots' plans and values when every robot's were usual, else None."""
        batch = self._batch
        targets: list[tuple[TargetPlan, TargetValues]] = []
        every = True
        for session, requests in received:
            usual = session.take_targets(requests) if batch is not None else None
            if usual is not None:
                targets.append(usual)
            else:
                every = False
                session.apply_all(requests, step_time_ms=step_time_ms)
        if targets:
            assert batch is not None
            batch.set_targets(targets)
        return targets if every else None

    def hold_notice(self, time_ms: int, text: str) -> int:
        """While the lockstep loop holds at ``time_ms`` (the referee waits for wall-clock time):
        each connected client not told yet during this hold gets one measurement of that time
        with ``text`` as a warning and no sensors; nothing else reaches it until the next step.
        The world is not touched: a notice changes nothing that is simulated. Returns the
        number of clients told now."""
        real_time = self._unix_ms()
        now = time.monotonic()
        told = 0
        for slot in self.slots.values():
            conn = slot.conn
            if conn is None or (id(conn), time_ms) in self._hold_told:
                continue
            self._hold_told.add((id(conn), time_ms))
            notice = Measurement(time_ms, real_time)
            notice.header.messages.add(message_type=WARNING, text=text)
            self._send(slot, conn, notice, now)
            told += 1
        if told:
            self._flush_all()
        return told

    def publish(self, time_ms: int) -> None:
        """Queue the measurement of the step that ended at ``time_ms`` for every client."""
        self.publish_prepared(self.prepare(time_ms))

    def prepare(self, time_ms: int) -> Prepared:
        """The measurements of the step that ended at ``time_ms`` for the connected clients,
        read but not queued: :meth:`publish_prepared` queues them. Pipelined stepping builds
        them before it waits for the answers to the previous ones. Without the I/O thread they
        are encoded here; with it the wire bytes are written there (``unwritten``, or
        ``steady`` when every robot is steady: see :class:`_SteadyStep`; then the step thread
        only reads the values)."""
        real_time = self._unix_ms()  # one instant for the whole step
        steady = self._steady_step
        if steady is not None and self._still_steady(steady, time_ms):
            values = steady.encoding.gather()
            return Prepared([], steady=_SteadyValues(steady, values, time_ms, real_time))
        items, gathered = self._prepare_each(time_ms, real_time)
        if gathered is not None and self._sender is None:
            gathered.write()
            gathered = None
        return Prepared(items, gathered)

    def _prepare_each(
        self, time_ms: int, real_time: int
    ) -> tuple[list[tuple[RobotSlot, Measurement]], Gathered | None]:
        """:meth:`prepare` robot by robot (each session's :meth:`RobotSession.begin_measure`);
        records the step's steady form when every robot is steady."""
        prepared: list[tuple[RobotSlot, Measurement]] = []
        batched: list[tuple[Measurement, DuePlan]] = []
        for slot in self.slots.values():
            if slot.conn is None:
                continue
            session = slot.session
            measurement, plan = session.begin_measure(time_ms, real_time)
            prepared.append((slot, measurement))
            if plan is None:
                continue
            if self._batch is not None:  # (its world gives every plan its sources)
                batched.append((measurement, plan))
            else:
                measurement.sensors = session.encode(plan)
        if not batched:
            self._steady_step = None
            return prepared, None
        assert self._batch is not None
        gathered = self._batch.gather(batched, header_bytes(time_ms, real_time))
        self._steady_step = self._steady_form(prepared, batched, gathered.encoding)
        return prepared, gathered

    def _steady_form(
        self,
        prepared: list[tuple[RobotSlot, Measurement]],
        batched: list[tuple[Measurement, DuePlan]],
        encoding: Encoding,
    ) -> _SteadyStep | None:
        """The :class:`_SteadyStep` of a step built robot by robot (``batched``, gathered
        with ``encoding``), or None when some robot was not steady, due at other steps than the
        others or still owed a camera image."""
        if self._removed_flags is None or len(batched) != len(prepared):
            return None
        first = prepared[0][0].session.steady
        if first is None:
            return None
        period, phase = first[0], first[1] % first[0]  # due when time % period is phase
        conns: list[Connection] = []
        for (slot, _), (_, plan) in zip(prepared, batched, strict=True):
            steady = slot.session.steady
            if steady is None or steady[2] is not plan or slot.pending or slot.conn is None:
                return None
            if steady[0] != period or steady[1] % period != phase:
                return None
            conns.append(slot.conn)
        return _SteadyStep(
            connection_changes=self.connection_changes,
            steady_changes=self._steady_changes.count,
            slots=tuple([slot for slot, _ in prepared]),
            conns=tuple(conns),
            plans=tuple([plan for _, plan in batched]),
            period=period,
            phase=phase,
            encoding=encoding,
        )

    def _still_steady(self, steady: _SteadyStep, time_ms: int) -> bool:
        """``steady`` holds for the step that ended at ``time_ms``: due by it, the same
        clients, no robot removed, no session's steady state changed."""
        return (
            time_ms % steady.period == steady.phase
            and steady.connection_changes == self.connection_changes
            and steady.steady_changes == self._steady_changes.count
            and self._removed_flags is not None
            and True not in self._removed_flags
        )

    def publish_prepared(self, prepared: Prepared) -> None:
        """Queue measurements made by :meth:`prepare` (a client dropped meanwhile gets none)."""
        steady = prepared.steady
        if steady is not None:
            if self._sender is not None and (
                steady.step.connection_changes == self.connection_changes
            ):
                self._publish_steady(steady)
                return
            # without the I/O thread, or a client left since: robot by robot
            assert self._batch is not None  # (a steady step is only recorded with the batch)
            prepared = Prepared(steady.measurements(self._batch))
        jobs_all = []
        now = time.monotonic()
        unwritten = prepared.unwritten
        for slot, measurement in prepared.items:
            conn = slot.conn
            if conn is None:
                continue
            jobs = measurement.jobs
            conn.owe()
            if jobs or slot.pending:  # sent by this thread when its images are in
                if unwritten is not None:
                    unwritten.write()
                    unwritten = None
                if jobs:
                    jobs_all.extend(jobs)
                slot.pending.append(_Pending(measurement, len(jobs)))
                self._maybe_waiting = True
            else:
                self._send(slot, conn, measurement, now)
        self._unwritten = unwritten
        if jobs_all:
            assert self._cameras is not None, "camera enabled without a render worker"
            self._cameras.submit(jobs_all)
            while self._cameras.in_flight > MAX_IN_FLIGHT and not self.stop_requested:
                self.poll(0.05)  # rendering is behind: let it catch up (results end the poll)
        self._flush_all()

    def _publish_steady(self, steady: _SteadyValues) -> None:
        """Hand a steady step's values to the I/O thread, which frames and queues them for
        every robot (:meth:`_deliver_steady`): what the step thread does per robot is the
        lockstep flag."""
        assert self._sender is not None
        if self._lockstep is not None:  # (the flag lockstep waits on; async never waits)
            for conn in steady.step.conns:
                conn.owe()
        self._flush_all()  # anything queued before, in order
        self._sender.submit(partial(self._deliver_steady, steady, time.monotonic()))

    def _send(
        self, slot: RobotSlot, conn: Connection, measurement: Measurement, now: float
    ) -> None:
        if conn.threaded:  # framed and queued on the I/O thread (handed over by _flush_all)
            self._outgoing.append((slot, conn, measurement))
            self._sent_at = now
            return
        frame = self._framed(slot, measurement)
        try:
            conn.send(frame, now)
        except ClientClosed as exc:
            self._drop(slot, exc.reason)

    def _framed(self, slot: RobotSlot, measurement: Measurement) -> bytes:
        """The measurement's framed message, counted in the robot's quota, or the quota's
        ERROR message in its place."""
        frame = measurement.frame
        if frame is not None:  # built whole by the step's batch: no header, no message
            return self._admitted(slot, frame, measurement.time, measurement.real_time)
        head, sensors = measurement.head(), measurement.sensors
        size = len(head) + len(sensors)
        if not slot.quota.admit(size, measurement.real_time):
            return self._quota_error(slot, measurement.time, measurement.real_time)
        warnings = measurement.message_count
        if warnings:
            slot.stats.warnings_sent += warnings
        return b"".join((HEADER.pack(size), head, sensors))

    def _admitted(self, slot: RobotSlot, frame: bytes, time_ms: int, real_time: int) -> bytes:
        """A plain measurement's whole ``frame``, counted in the robot's quota, or the quota's
        ERROR message in its place."""
        if slot.quota.admit(len(frame) - HEADER.size, real_time):
            return frame
        return self._quota_error(slot, time_ms, real_time)

    def _quota_error(self, slot: RobotSlot, time_ms: int, real_time: int) -> bytes:
        """The framed ERROR message that replaces a measurement over the robot's quota."""
        quota = slot.quota
        slot.stats.quota_errors += 1
        header = pb.SensorMeasurements(time=time_ms, real_time=real_time)
        header.messages.add(message_type=ERROR, text=quota.error_text)
        payload: bytes = header.SerializeToString()
        quota.record(len(payload), real_time)
        slot.stats.warnings_sent += 1
        return HEADER.pack(len(payload)) + payload

    def _flush_all(self) -> None:
        if self._sender is not None:
            if self._sender.failure is not None:
                raise IoThreadFailed(self._sender.failure) from self._sender.failure
            if self._outgoing or self._unwritten is not None:
                self._sender.submit(partial(self._deliver, self._outgoing, self._unwritten,
                                            self._sent_at))  # fmt: skip
                self._outgoing = []
                self._unwritten = None
            return
        blocking = self._network.blocking_send
        for slot in self.slots.values():
            if slot.conn is None or slot.conn.idle:
                continue
            self._flush(slot)
            if blocking:
                self._flush_blocking(slot)

    def _deliver(
        self,
        outgoing: list[tuple[RobotSlot, Connection, Measurement]],
        unwritten: Gathered | None,
        now: float,
    ) -> list[Connection]:
        """I/O thread: write the step's wire bytes, frame each measurement (counted in its
        robot's quota) and queue it; the connections to write to. The step thread is back in
        the physics meanwhile (MuJoCo releases the GIL while it steps)."""
        if unwritten is not None:
            unwritten.write()
        queued = []
        for slot, conn, measurement in outgoing:
            if conn.closed or conn.error is not None:
                continue  # dropped since: the step thread forgets it
            conn.send_threaded(self._framed(slot, measurement), now)
            queued.append(conn)
        return queued

    def _deliver_steady(self, steady: _SteadyValues, now: float) -> list[Connection]:
        """I/O thread: :meth:`_deliver` of a steady step: the wire bytes of every robot's plain
        measurement written at once, each counted in its robot's quota and queued."""
        assert self._batch is not None
        step = steady.step
        frames = steady.frames(self._batch)
        queued = []
        for slot, conn, frame in zip(step.slots, step.conns, frames, strict=True):
            if conn.closed or conn.error is not None:
                continue  # dropped since: the step thread forgets it
            conn.send_threaded(self._admitted(slot, frame, steady.time_ms, steady.real_time), now)
            queued.append(conn)
        return queued

    def _flush_blocking(self, slot: RobotSlot) -> None:
        """HLVS behaviour: wait until the client has taken everything (stalls the step)."""
        while slot.conn is not None and not slot.conn.idle and not self.stop_requested:
            conn = slot.conn
            with selectors.DefaultSelector() as one:
                one.register(conn.sock, selectors.EVENT_WRITE)
                one.select(0.1)
            self._flush(slot)

    def _camera_results(self) -> None:
        assert self._cameras is not None
        touched: set[RobotId] = set()
        for job, image in self._cameras.completed():
            slot = self.slots[job.robot]
            job.measurement.image = image
            for pending in slot.pending:
                if pending.measurement.time == job.time_ms and pending.missing:
                    pending.missing -= 1
                    break
            touched.add(job.robot)
        now = time.monotonic()
        for robot in touched:
            slot = self.slots[robot]
            while slot.pending and slot.pending[0].missing == 0 and slot.conn is not None:
                self._send(slot, slot.conn, slot.pending.popleft().measurement, now)
        self._flush_all()


def _refuse(sock: socket.socket) -> None:
    try:
        sock.setblocking(False)
        sock.send(REFUSED)
    except OSError:
        pass  # the peer is gone already; nothing to tell it
    finally:
        sock.close()
