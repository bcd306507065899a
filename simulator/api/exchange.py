"""Plain lockstep's steady exchange in compiled code, on a thread of its own.

In plain lockstep the step thread sends every robot's measurement, waits for their answers and
only then steps the world. On a steady step (every robot steady, the target board armed,
nothing queued, no camera) all of that is the same few system calls per robot, and the world's
next first position stage (``mj_step1``, about a tenth of the step) needs no answer. So the
step thread hands the step's frames to :class:`Exchange` (``native/exchange.c``, loaded with
:mod:`ctypes` and built once by the machine's C compiler, as the project's other small C
programs): its thread sends them, reads the answers and writes the usual ones straight onto the
board's spans, while the step thread computes that stage (:meth:`World.prefetch` inline) and
then waits. What the thread cannot take as one whole usual request (more than one frame, another
layout, an empty request, the end of the stream, a send the socket did not take whole, an
error, a frame still open at the lockstep deadline) it hands back with the bytes it received,
and the step thread goes on with them exactly as its own reads would have
(:func:`settle`). The counting of a step whose every answer was taken (each connection's
statistics, round trip and lockstep flag) is done while the next step's exchange is under way
(:meth:`Exchange.count_owed`; the server's statistics count it first).

The two threads hand over through flags that each spins on before it sleeps (the exchange thread
for the next step up to :data:`SPIN_S`, while the world steps and the clients are idle; the step
thread for the answers up to :data:`WAIT_SPIN_S`, while the clients may need the CPUs), so steps
that follow each other closely cost no wake-up between processors. The exchange is
used only where the process may run on two CPUs or more (a spinning thread on a machine's only
CPU would take it from the world) and a C compiler is here: otherwise plain lockstep's own
reads and sends run as before. ``HLVS_EXCHANGE=0`` turns it off.
"""

from __future__ import annotations

import ctypes
import logging
import os
import time
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any, Protocol, cast

import numpy as np
import numpy.typing as npt

from simulator.api.connection import exchanged, written_elsewhere

if TYPE_CHECKING:
    from simulator.api.board import BoardSlot
    from simulator.api.connection import Connection
    from simulator.api.fastreq import PositionTemplate
    from simulator.api.slots import RobotSlot

log = logging.getLogger(__name__)

SOURCE = Path(__file__).with_name("native") / "exchange.c"
SPIN_S = 0.002  # the exchange thread waiting for the next step
WAIT_SPIN_S = 0.001  # the step thread waiting for the answers (the clients may need the CPU)
MAX_ROBOTS = 64
PENDING, TAKEN, HANDED, RECV_ERROR, SEND_SHORT, SEND_ERROR = range(6)
_RESULTS = (("status", np.int32), ("error", np.int32), ("sent", np.int64),
            ("received", np.int64), ("sent_at", np.float64), ("first_at", np.float64),
            ("answered_at", np.float64))  # fmt: skip


def _library() -> ctypes.CDLL | None:
    """The compiled exchange (built now if this version has not been), or None with the
    reason logged."""
    from simulator import native_build

    try:
        path = native_build.build_native(SOURCE, "simulator",
                                  flags=("-O2", "-shared", "-fPIC", "-pthread"))  # fmt: skip
        lib = ctypes.CDLL(str(path))
    except (native_build.NativeBuildError, OSError) as exc:
        reason = exc.reason if isinstance(exc, native_build.NativeBuildError) else str(exc)
        log.info("plain lockstep's exchange thread is not used: %s", reason)
        return None
    pointer, c_int, c_double = ctypes.c_void_p, ctypes.c_int, ctypes.c_double
    lib.ex_create.restype = pointer
    lib.ex_create.argtypes = [pointer, c_int, c_double, c_double]
    lib.ex_robot.restype = c_int
    lib.ex_robot.argtypes = [pointer, c_int, c_int, pointer, c_int, pointer, c_int, pointer]
    lib.ex_clear.restype = None
    lib.ex_clear.argtypes = [pointer]
    lib.ex_go.restype = None
    lib.ex_go.argtypes = [pointer, c_int, pointer, pointer]
    lib.ex_wait.restype = c_int
    lib.ex_wait.argtypes = [pointer, c_double]
    lib.ex_results.restype = pointer
    lib.ex_results.argtypes = [pointer]
    lib.ex_buffer.restype = ctypes.POINTER(ctypes.c_ubyte)
    lib.ex_buffer.argtypes = [pointer, c_int]
    lib.ex_close.restype = None
    lib.ex_close.argtypes = [pointer]
    return lib


def wanted(cpus: frozenset[int] | None) -> bool:
    """Whether a server whose exchange thread may use ``cpus`` (None: the process's) should
    run one: two CPUs or more between the step thread and it, and not turned off."""
    if os.environ.get("HLVS_EXCHANGE", "1") == "0":
        return False
    allowed = os.sched_getaffinity(0) | (cpus or frozenset())
    return len(allowed) >= 2


def template_layout(template: PositionTemplate) -> tuple[bytes, npt.NDArray[np.int32]]:
    """A usual request's body with its targets zeroed, and where each 8-byte target starts."""
    offsets, parts, at = [], [], 0
    for segment in template.fixed:
        parts.append(segment)
        at += len(segment)
        offsets.append(at)
        parts.append(bytes(8))
        at += 8
    return b"".join(parts), np.asarray(offsets, dtype=np.int32)


@dataclass(slots=True)
class ExchangeRun:
    """One step's exchange in flight: its robots (in the order of the frames) and frames."""

    slots: tuple[RobotSlot, ...]
    conns: tuple[Connection, ...]
    spans: tuple[BoardSlot, ...]
    frames: memoryview
    frame_spans: tuple[tuple[int, int], ...]


class Exchange:
    """The compiled exchange and its thread (one per server; :meth:`close` ends it)."""

    def __init__(self, lib: ctypes.CDLL, handle: int) -> None:
        self._lib = lib
        self._handle = handle
        base = lib.ex_results(handle)
        self.results: dict[str, npt.NDArray[np.generic]] = {}
        offset = 0
        for name, dtype in _RESULTS:
            size = np.dtype(dtype).itemsize * MAX_ROBOTS
            raw = (ctypes.c_char * size).from_address(base + offset)
            self.results[name] = np.frombuffer(memoryview(raw).cast("B"), dtype=dtype)
            offset += size
        self._registered: list[tuple[BoardSlot, PositionTemplate]] = []
        self._board_slots: tuple[BoardSlot, ...] = ()
        # the boards the engine writes into (it copied the layouts it was given)
        self._keep: list[object] = []
        # this step's frames for the engine, kept while the same objects come back
        self._spans_of: object = None
        self._spans: npt.NDArray[np.int64] = np.zeros(0, dtype=np.int64)
        self._frames_of: object = None
        self._frames_at = 0
        self._go = lib.ex_go
        self._wait = lib.ex_wait
        self.run: ExchangeRun | None = None
        self.steps = 0  # exchanges started
        self.taken = 0  # robots' answers taken onto the board
        self.handed_back = 0  # robots' answers handed back to the step thread's reads
        # the last step's exchange took every answer: nothing is left for the step thread
        self.clean = False
        # its counting, done while the next exchange is under way (:meth:`count_owed`)
        self.owed: tuple[tuple[Connection, ...], tuple[list[Any], ...]] | None = None

    @classmethod
    def start(cls, cpus: frozenset[int] | None) -> Exchange | None:
        """An exchange whose thread runs on ``cpus`` (None: wherever the process may), or None
        when it cannot be built or started here (logged)."""
        lib = _library()
        if lib is None:
            return None
        chosen = sorted(cpus or ())
        array = (ctypes.c_int * max(1, len(chosen)))(*chosen)
        handle = lib.ex_create(array, len(chosen), SPIN_S, WAIT_SPIN_S)
        if not handle:
            log.info("plain lockstep's exchange thread could not start")
            return None
        return cls(lib, handle)

    def close(self) -> None:
        if self._handle:
            self.wait(0.0)
            self.count_owed()
            self._lib.ex_close(self._handle)
            self._handle = 0

    def begin(self, slots: tuple[RobotSlot, ...], conns: tuple[Connection, ...],
              frames: memoryview, frame_spans: tuple[tuple[int, int], ...]) -> bool:
        """Start the exchange of a steady step's ``frames`` (robot ``i``'s at
        ``frame_spans[i]``) when every client is on the target board with its usual request's
        layout and nothing buffered, queued, paused or unwritten: True when it started (the
        caller then counts each measurement as sent:
        :func:`~simulator.api.connection.sent_elsewhere`)."""
        self.clean = False
        board_spans = []
        for conn in conns:
            span = cast("BoardSlot | None", conn.board)
            template = conn.template
            if (
                span is None or template is None or template.names is not span.names
                or not conn.idle or conn.paused or conn.slow or conn.requests
                or conn.decoder.buffered or conn.preread
            ):  # fmt: skip
                return False
            board_spans.append((span, template))
        if board_spans != self._registered and not self._register(conns, board_spans):
            return False
        if frame_spans is not self._spans_of:
            self._spans_of = frame_spans
            self._spans = np.asarray(frame_spans, dtype=np.int64)
        source = frames.obj
        if source is not self._frames_of:
            self._frames_of = source
            self._frames_at = np.frombuffer(frames, dtype=np.uint8).ctypes.data
        self._go(self._handle, len(conns), self._frames_at, self._spans.ctypes.data)
        self.run = ExchangeRun(slots, conns, self._board_slots, frames, frame_spans)
        self.steps += 1
        return True

    def _register(self, conns: tuple[Connection, ...],
                  board_spans: list[tuple[BoardSlot, PositionTemplate]]) -> bool:
        """Make ``conns`` (their sockets, usual requests' layouts and board spans) the robots of
        the next exchanges; False when the engine refused one."""
        self._registered = []
        self._lib.ex_clear(self._handle)
        keep: list[object] = []
        for index, (conn, (span, template)) in enumerate(zip(conns, board_spans, strict=True)):
            body, offsets = template_layout(template)
            values = span.board.values
            destination = values.ctypes.data + span.start * values.itemsize
            keep.append(values)
            if self._lib.ex_robot(self._handle, index, conn.fd, body, len(body),
                                  offsets.ctypes.data, len(offsets), destination) != 0:
                return False  # fmt: skip
        self._keep = keep
        self._registered = board_spans
        self._board_slots = tuple([span for span, _ in board_spans])
        return True

    def count_owed(self) -> None:
        """Count what the last exchange that took every answer sent and read
        (:func:`~simulator.api.connection.exchanged`), if not counted yet."""
        owed = self.owed
        if owed is None:
            return
        self.owed = None
        conns, (sent, sent_at, received, first_at, answered_at) = owed
        for index, conn in enumerate(conns):
            exchanged(conn, sent[index], sent_at[index], received[index], first_at[index],
                      answered_at[index])  # fmt: skip

    def wait(self, wait_s: float) -> ExchangeRun | None:
        """Wait for the exchange in flight (reading answers for ``wait_s`` at most); the run
        it was, or None when none was in flight."""
        run, self.run = self.run, None
        if run is not None:
            self._wait(self._handle, wait_s)
        return run

    def received(self, index: int) -> bytes:
        """What robot ``index`` of the last exchange sent that the engine did not take."""
        if self.results["status"][index] == TAKEN:
            return b""
        size = int(self.results["received"][index])
        return ctypes.string_at(self._lib.ex_buffer(self._handle, index), size) if size else b""


class SlotPorts(Protocol):
    """What :func:`settle` needs of the server's ports (:class:`simulator.api.ports.Ports`)."""

    def drop(self, slot: RobotSlot, reason: str) -> None: ...

    def flush(self, slot: RobotSlot) -> None: ...

    def read(self, slot: RobotSlot, now: float) -> None: ...


def settle(exchange: Exchange, ports: SlotPorts, wait_s: float) -> None:
    """End the exchange in flight: wait for its thread (reading answers for ``wait_s`` at
    most). When it took every answer onto the board, the board's spans are marked posted and
    the counting of each robot's measurement as written and its answer as read
    (:func:`~simulator.api.connection.exchanged`) waits in ``exchange.owed`` until
    :meth:`Exchange.count_owed` (the step thread does it while the next exchange is under way).
    Otherwise it is done now, and the rest goes on robot by robot as the step thread's own
    sends and reads would have: a failed send or receive drops the client, the part of a
    measurement the socket did not take waits in its connection, the bytes of an answer not
    taken are read by the connection (:attr:`Connection.preread`)."""
    run = exchange.wait(wait_s)
    if run is None:
        return
    exchange.count_owed()
    results = exchange.results
    count = len(run.conns)
    status = results["status"][:count].tolist()
    figures = (results["sent"][:count].tolist(), results["sent_at"][:count].tolist(),
               results["received"][:count].tolist(), results["first_at"][:count].tolist(),
               results["answered_at"][:count].tolist())  # fmt: skip
    spans = run.spans
    taken = status.count(TAKEN)
    exchange.taken += taken
    if taken == count:  # the usual case
        exchange.clean = True
        board = spans[0].board if spans else None
        if board is not None and len(board.slots) == count:
            board.fresh = [True] * count  # (every robot of the board is in the exchange)
        else:
            for span in spans:
                span.board.fresh[span.index] = True
        exchange.owed = (run.conns, figures)
        return
    exchange.clean = False
    for index, (conn, span) in enumerate(zip(run.conns, spans, strict=True)):
        if status[index] == TAKEN:
            exchanged(conn, *(column[index] for column in figures))
            span.board.fresh[span.index] = True
        else:
            _settle_one(exchange, ports, run, index, status[index])


def _settle_one(exchange: Exchange, ports: SlotPorts, run: ExchangeRun, index: int,
                state: int) -> None:
    """:func:`settle` of robot ``index`` of ``run``, whose answer the engine did not take."""
    slot, conn = run.slots[index], run.conns[index]
    if slot.conn is not conn:
        return  # dropped meanwhile
    results = exchange.results
    if state == SEND_ERROR:
        ports.drop(slot, f"send failed: {_error_text(int(results['error'][index]))}")
        return
    start, end = run.frame_spans[index]
    written = int(results["sent"][index])
    written_elsewhere(conn, written, run.frames[start + written : end],
                      float(results["sent_at"][index]))  # fmt: skip
    if state == SEND_SHORT:
        ports.flush(slot)
        return
    if state == RECV_ERROR:
        ports.drop(slot, f"receive failed: {_error_text(int(results['error'][index]))}")
        return
    data = exchange.received(index)
    if data or state == HANDED:
        exchange.handed_back += 1
        conn.preread = data
        ports.read(slot, time.monotonic())


def _error_text(number: int) -> str:
    return f"[Errno {number}] {os.strerror(number)}"
