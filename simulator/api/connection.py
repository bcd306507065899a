"""One accepted robot API client: non-blocking reads and writes with a bounded send queue."""

from __future__ import annotations

import logging
import socket
import threading
import time
from collections import deque
from collections.abc import Sequence
from typing import Protocol

from google.protobuf.message import DecodeError

from contracts.robot_api import messages_pb2 as pb
from simulator.api.bounds import (
    BYTE_COST,
    FRAME_COST,
    MAX_REQUEST_BYTES,
    READ_PER_CALL_BYTES,
    ReadBudget,
)
from simulator.api.fastreq import Notice, PositionTargets, PositionTemplate, scan_positions
from simulator.api.framing import FrameDecoder, FramingError
from simulator.api.stats import RobotStats

log = logging.getLogger(__name__)

Request = pb.ActuatorRequests | PositionTargets | Notice
RECV_CHUNK = 1 << 16
# Linux: acknowledge at once, not after the delayed-ACK timer (the kernel clears it again)
TCP_QUICKACK: int | None = getattr(socket, "TCP_QUICKACK", None)


class BoardPost(Protocol):
    """Where a connection's decoded requests go while the server's target board is armed
    (:class:`simulator.api.board.BoardSlot`)."""

    def post(
        self,
        decoded: Sequence[Request],
        queue: list[Request],
    ) -> None: ...

    def post_values(self, names: tuple[str, ...], values: Sequence[float]) -> bool: ...


class AnswerBook:
    """Who lockstep waits for, kept as it changes so that "has every client answered?" is one
    look whatever the number of robots: ``owing``, the connections not slow whose latest
    measurement is not answered yet, and ``slow``, those lockstep does not wait for. A
    connection moves between them itself (:meth:`Connection.owe`, its reads, its
    :meth:`Connection.mark_slow`); an add or a discard on a set is one operation under the GIL,
    so the I/O thread's reads may move one while the step thread looks."""

    __slots__ = ("owing", "slow")

    def __init__(self) -> None:
        self.owing: set[Connection] = set()
        self.slow: set[Connection] = set()

    def forget(self, conn: Connection) -> None:
        """``conn`` is dropped: nobody waits for it."""
        self.owing.discard(conn)
        self.slow.discard(conn)

    def reconcile(self) -> None:
        """Take out of ``owing`` what a race between the two threads left there (a connection
        marked slow while it was being owed, or closed); the flags are the authority."""
        for conn in tuple(self.owing):
            if conn.slow or conn.answered or conn.closed:
                self.owing.discard(conn)


class ClientClosed(Exception):
    """Internal signal: the client must be dropped; ``reason`` says why (logged once)."""

    def __init__(self, reason: str) -> None:
        self.reason = reason
        super().__init__(reason)


class Connection:
    """The connected client of one robot port.

    ``answered`` is the lockstep flag: a request arrived after the last measurement was queued
    (a new connection owes its first request). Requests are decoded on arrival and kept until the
    step loop applies them: a request of position targets in the layout of the client's previous
    one as :class:`PositionTargets` (no protobuf, see :mod:`simulator.api.fastreq`), any other
    as ``ActuatorRequests``.
    """

    def __init__(
        self,
        *,
        sock: socket.socket,
        peer: str,
        key: str,
        stats: RobotStats,
        queue_limit: int,
        time_bank_s: float,
        threaded: bool = False,
        requests_lock: threading.Lock | None = None,
    ) -> None:
        """``threaded``: a :class:`simulator.api.sender.SendThread` reads the socket and writes
        the queue; the step thread only appends to the queue (:meth:`send`), takes the decoded
        requests (:meth:`take_requests`) and drops the client when ``error`` is set.
        ``requests_lock``: guards ``requests`` and ``board`` (the server shares one between its
        connections: :mod:`simulator.api.board`)."""
        self.sock = sock
        self.fd = sock.fileno()
        self.threaded = threaded
        self.closed = False
        self.error: str | None = None  # set by the I/O thread: the step thread drops the client
        self._lock = threading.Lock()  # the I/O thread's reads and writes against close()
        self.requests_lock = requests_lock if requests_lock is not None else threading.Lock()
        self.peer = peer
        self.key = key
        self.stats = stats
        self.queue_limit = max(1, queue_limit)
        self.decoder = FrameDecoder()
        self.budget = ReadBudget(time.monotonic())
        self.max_request_bytes = MAX_REQUEST_BYTES
        self.paused = False  # the budget is spent: not read (nor watched) until it refills
        self.measurements = 0  # queued so far (each refills the budget)
        self._paused_logged = 0.0  # when a pause was last logged (one line per 10 s)
        self.requests: list[Request] = []
        self.board: BoardPost | None = None  # usual requests go there while armed (board.py)
        self.template: PositionTemplate | None = None  # the layout of its usual request
        self.preread = b""  # received by the exchange thread and handed back: read first
        self.outbox: deque[bytes] = deque()
        self._partial: memoryview | None = None
        self.answered = False
        self.answered_at = 0.0
        self.last_sent_at: float | None = None
        # the client's round trip seen from here (``stats.reply_s``): when the first byte of the
        # oldest request not yet followed by a measurement, and of the frame being received, came
        self._request_began: float | None = None
        self._frame_began: float | None = None
        self.enqueued_at = 0.0  # monotonic time the latest measurement was queued
        self.slow = False
        self.book: AnswerBook | None = None  # lockstep's (None without lockstep): the server's
        self.bank_s = time_bank_s
        self.want_write = False
        self._told = False  # a request dropped with a notice since the last read's end

    def fileno(self) -> int:
        return self.sock.fileno()

    # --- reading ----------------------------------------------------------------------------

    def read(self, now: float) -> int:
        """Read what is available and the budget pays for (:mod:`simulator.api.bounds`), at
        most :data:`READ_PER_CALL_BYTES` (the rest waits for the next call); returns the number
        of requests taken. Bytes are charged as they are received and frames as they are cut
        out, before anything else is done with them; when the budget is spent the connection is
        ``paused`` (not read until :meth:`resume` says it refilled) and marked slow. A request
        over the size limit is dropped undecoded, counted and told to the client. Raises
        ClientClosed on EOF, a socket error, a framing error or an undecodable message."""
        count = taken = 0
        acked = False  # an ACK was sent since the last bytes were received
        budget = self.budget
        level = budget.refill(now, self.measurements)
        decoder = self.decoder
        began = self._frame_began if decoder.buffered and self._frame_began is not None else now
        try:
            while True:
                if level < FRAME_COST:
                    self._pause(now)
                    break
                if decoder.held:  # frames the budget did not pay for last time: no receive
                    data = b""
                elif self.preread:  # (simulator.api.exchange)
                    data, self.preread = self.preread, b""
                else:
                    try:
                        data = self.sock.recv(RECV_CHUNK)
                    except (BlockingIOError, InterruptedError):
                        break
                    except OSError as exc:
                        raise ClientClosed(f"receive failed: {exc}") from exc
                    if not data:
                        raise ClientClosed("client disconnected")
                if data:
                    acked = False
                    self.stats.bytes_in += len(data)
                    taken += len(data)
                    level -= len(data) * BYTE_COST
                try:
                    frames = decoder.feed(data, int(level // FRAME_COST))
                except FramingError as exc:
                    self.stats.bad_frames += 1
                    raise ClientClosed(f"out of sync: {exc}") from exc
                if frames:
                    level -= len(frames) * FRAME_COST
                    count += self._take(frames)
                if decoder.held:
                    continue  # more frames buffered: taken while the budget pays
                if len(data) < RECV_CHUNK or taken >= READ_PER_CALL_BYTES:
                    if decoder.buffered and not acked and taken < READ_PER_CALL_BYTES:
                        self._quick_ack()  # inside a frame: the rest may follow the ACK at once
                        acked = True
                        if level >= FRAME_COST:  # a second look, not a pause, when spent
                            continue
                    break
        finally:
            budget.level = level
            self.stats.messages_in += count  # also when a close ends the read: they were taken
        if decoder.buffered:
            if not acked:
                self._quick_ack()
            self._frame_began = now if count else began
        else:
            self._frame_began = None
        if count:
            if self._request_began is None:
                self._request_began = began
        if count or self._told:
            self._told = False
            self.answered = True
            self.answered_at = now
            book = self.book
            if book is not None:
                book.owing.discard(self)
            if self.last_sent_at is not None:
                self.stats.round_trip_s.append(now - self.last_sent_at)
                self.last_sent_at = None
        return count

    def _quick_ack(self) -> None:
        """Acknowledge what was received now, not after the delayed-ACK timer (40 ms on
        Linux): the league's client (``robot_client.cpp:171-179``) writes the length and the
        body apart without ``TCP_NODELAY``, so Nagle holds the body until that ACK. On loopback
        the body has usually arrived when the call returns: :meth:`read` looks once more
        (``simulator/api/README.md``). Only when a read ends inside a frame."""
        option = TCP_QUICKACK
        if option is None:
            return
        try:
            self.sock.setsockopt(socket.IPPROTO_TCP, option, 1)
        except OSError:
            pass  # the socket is failing: the next read says so

    def _take(self, frames: list[bytes]) -> int:
        """Decode ``frames`` (paid for) and queue them, or post them on the server's target
        board; returns how many answered (all but those over the size limit)."""
        if _onto_board(self, frames):
            return 1
        template = self.template
        decoded: list[Request] = []
        answers = 0
        for frame in frames:
            if len(frame) > self.max_request_bytes:
                self.stats.drop_in("size", len(frame))
                decoded.append(Notice(
                    f"ActuatorRequests of {len(frame)} bytes is above the limit of"
                    f" {self.max_request_bytes} bytes, ignored."
                ))  # fmt: skip
                self._told = True  # an answer all the same: lockstep waits for no other
                continue
            answers += 1
            if not frame:  # an empty ActuatorRequests: an answer with nothing to apply
                continue
            targets = template.match(frame) if template is not None else None
            if targets is not None:
                decoded.append(targets)
            else:
                decoded.append(self._parse(frame))
                template = self.template
        if decoded:
            with self.requests_lock:
                board = self.board
                if board is None:
                    self.requests.extend(decoded)
                else:
                    board.post(decoded, self.requests)
        return answers

    def _pause(self, now: float) -> None:
        """The budget is spent: stop reading (the caller stops watching the socket) and mark
        the robot slow, as lockstep marks a robot out of time."""
        self.paused = True
        if self.slow:
            return
        self.mark_slow(True)
        self.stats.slow_periods += 1
        if now - self._paused_logged >= 10.0:
            self._paused_logged = now
            log.warning(
                "%s: sends more requests than its budget of %g a second and %g a measurement"
                " pays for: not read until the budget refills, and not waited for in lockstep"
                " meanwhile (%d times so far)",
                self.key, self.budget.rate, self.budget.per_measurement, self.stats.slow_periods,
            )  # fmt: skip

    def owe(self) -> None:
        """A measurement was queued: the client owes its answer (lockstep waits for it unless
        it is slow)."""
        self.answered = False
        book = self.book
        if book is not None and not self.slow:
            book.owing.add(self)

    def mark_slow(self, slow: bool) -> None:
        """Lockstep stops (True) or starts again (False) waiting for this client."""
        self.slow = slow
        book = self.book
        if book is None:
            return
        if slow:
            book.slow.add(self)
            book.owing.discard(self)
        else:
            book.slow.discard(self)
            if not self.answered:
                book.owing.add(self)

    def resume(self, now: float) -> bool:
        """A paused connection whose budget refilled is no longer paused: True, and the caller
        watches its socket again and reads it (frames may be buffered)."""
        if self.budget.refill(now, self.measurements) < FRAME_COST:
            return False
        self.paused = False
        return True

    def read_threaded(self, now: float) -> bool:
        """I/O thread: :meth:`read`, leaving a failure in ``error`` for the step thread.
        True when the step thread has something new: requests, an answer dropped for its size
        (its notice), or a failure."""
        with self._lock:
            if self.closed or self.error is not None:
                return False
            answered_at = self.answered_at
            try:
                return self.read(now) > 0 or self.answered_at != answered_at
            except ClientClosed as exc:
                self.error = exc.reason
                return True

    def take_requests(self) -> list[Request]:
        """The requests received since the last call, in arrival order."""
        with self.requests_lock:
            requests, self.requests = self.requests, []
        return requests

    def _parse(self, frame: bytes) -> pb.ActuatorRequests:
        request = pb.ActuatorRequests()
        try:
            request.ParseFromString(frame)
        except DecodeError as exc:
            self.stats.decode_errors += 1
            raise ClientClosed(f"undecodable ActuatorRequests ({len(frame)} bytes)") from exc
        if request.motor_positions and len(request.ListFields()) == 1:
            template = scan_positions(frame)
            if template is not None:
                self.template = template
        return request

    # --- writing ----------------------------------------------------------------------------

    def enqueue(self, frame: bytes, now: float) -> None:
        """Queue one framed measurement; the oldest queued ones are dropped when full."""
        outbox = self.outbox
        while len(outbox) >= self.queue_limit:
            try:
                outbox.popleft()
            except IndexError:  # threaded: the I/O thread took it meanwhile
                break
            self.stats.dropped_out += 1
        outbox.append(frame)
        self.measurements += 1
        self.owe()
        self.last_sent_at = now
        self.enqueued_at = now

    def send(self, frame: bytes | memoryview, now: float) -> None:
        """:meth:`enqueue` and :meth:`flush`, but a frame with nothing queued before it goes
        straight to the socket (the usual case). Threaded: only :meth:`enqueue`. A view is of
        a buffer the caller reuses (plain lockstep): what the socket does not take is copied.

        Raises:
            ClientClosed: on a fatal send error.
        """
        if self.threaded or self._partial is not None or self.outbox:
            kept = frame if isinstance(frame, bytes) else frame.tobytes()
            if self.threaded:
                return self.send_threaded(kept, now)
            self.enqueue(kept, now)
            self.flush()
            return
        self.measurements += 1
        self.owe()
        self.last_sent_at = now
        self.enqueued_at = now
        stats = self.stats
        stats.messages_out += 1
        try:
            sent = self.sock.send(frame)
        except (BlockingIOError, InterruptedError):
            sent = 0
        except OSError as exc:
            raise ClientClosed(f"send failed: {exc}") from exc
        stats.bytes_out += sent
        if sent < len(frame):
            self._partial = memoryview(bytes(frame[sent:]))  # a view's rest is copied
            self.want_write = True
        else:
            self._written(monotonic())

    def send_threaded(self, frame: bytes, now: float) -> None:
        """:meth:`send` of a threaded connection: queue the frame for the I/O thread (never
        raises: a failure is left in ``error``)."""
        if len(self.outbox) >= self.queue_limit:
            self.write_queued()  # the I/O thread is behind: the socket may still take them
        self.enqueue(frame, now)

    def write_queued(self) -> bool:
        """:meth:`flush` for the I/O thread (and for the step thread when the I/O thread is
        behind and the queue is full): True when nothing is left to wait for (all written, or
        the connection failed or closed), False when the socket is full. A failure is left in
        ``error``."""
        with self._lock:
            if self.closed or self.error is not None:
                return True
            try:
                return self.flush()
            except ClientClosed as exc:
                self.error = exc.reason
                return True

    def flush(self) -> bool:
        """Write as much as the socket takes; True when everything queued was written.

        Raises:
            ClientClosed: on a fatal send error.
        """
        sock = self.sock
        while True:
            if self._partial is None:
                try:
                    frame = self.outbox.popleft()
                except IndexError:  # all written
                    self.want_write = False
                    return True
                self.stats.messages_out += 1
                self._partial = memoryview(frame)
            try:
                sent = sock.send(self._partial)
            except (BlockingIOError, InterruptedError):
                self.want_write = True
                return False
            except OSError as exc:
                raise ClientClosed(f"send failed: {exc}") from exc
            self.stats.bytes_out += sent
            if sent == len(self._partial):
                self._partial = None
                self._written(monotonic())
            else:
                self._partial = self._partial[sent:]

    def _written(self, at: float) -> None:
        """A measurement's last byte is written at ``at``: the client's part of the round trip
        starts, and the client's round trip as seen here (``reply_s``: from its request's
        first byte to this measurement written, what a client that waits for each
        measurement measures less the two transits) ends."""
        self.last_sent_at = at
        began = self._request_began
        if began is not None:
            self.stats.reply_s.append(at - began)
            self._request_began = None

    @property
    def idle(self) -> bool:
        return self._partial is None and not self.outbox

    def close(self) -> None:
        with self._lock:
            self.closed = True
            try:
                self.sock.close()
            except OSError:  # already gone; nothing left to release
                pass


def _onto_board(conn: Connection, frames: list[bytes]) -> bool:
    """One frame of the usual request of a robot on the server's target board straight onto
    its span (no request object made: :meth:`BoardPost.post_values`), when it has the layout
    of the connection's template, every target is finite and nothing is queued before it;
    False otherwise (the caller takes it the usual way)."""
    template = conn.template
    if len(frames) != 1 or template is None or conn.board is None:
        return False
    frame = frames[0]
    if len(frame) > conn.max_request_bytes:
        return False
    values = template.finite_values(frame)
    if values is None:
        return False
    with conn.requests_lock:
        span = conn.board
        return span is not None and not conn.requests and span.post_values(template.names, values)


def sent_elsewhere(conn: Connection, now: float) -> None:
    """A measurement is being written to ``conn``'s socket by plain lockstep's exchange thread
    (:mod:`simulator.api.exchange`): counted and owed as :meth:`Connection.send` counts and
    owes one; :func:`written_elsewhere` or :func:`exchanged` when the thread is done."""
    conn.measurements += 1
    conn.owe()
    conn.last_sent_at = now
    conn.enqueued_at = now
    conn.stats.messages_out += 1


def written_elsewhere(conn: Connection, sent: int, rest: memoryview, at: float) -> None:
    """The exchange thread wrote ``sent`` bytes of the measurement at ``at``; ``rest`` (copied)
    is what the socket did not take, written by :meth:`Connection.flush`."""
    conn.stats.bytes_out += sent
    if rest:
        conn._partial = memoryview(bytes(rest))
        conn.want_write = True
    else:
        conn._written(at)


def exchanged(conn: Connection, sent: int, sent_at: float, received: int, first_at: float,
              answered_at: float) -> None:  # fmt: skip
    """The exchange thread wrote the whole measurement (``sent`` bytes, at ``sent_at``) and
    took one usual request of ``received`` bytes onto the board, whose first bytes arrived at
    ``first_at`` and its last at ``answered_at``: counted and answered as
    :meth:`Connection.send` and :meth:`Connection.read` count and answer them. Its budget is
    not charged: one frame answering one measurement is what the budget's refill per
    measurement always pays for."""
    stats = conn.stats
    stats.bytes_out += sent
    began = conn._request_began
    if began is not None:  # (:meth:`Connection._written`)
        stats.reply_s.append(sent_at - began)
    conn._request_began = first_at
    conn.last_sent_at = None
    stats.bytes_in += received
    stats.messages_in += 1
    conn.answered = True
    conn.answered_at = answered_at
    book = conn.book
    if book is not None:
        book.owing.discard(conn)
    stats.round_trip_s.append(answered_at - sent_at)


def monotonic() -> float:
    return time.monotonic()
