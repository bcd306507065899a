"""Every robot's usual position targets, from the I/O thread to the world in one write.

Nearly every request of a playing robot is the usual one: position targets for the motor names
it sent before, read finite. Once a step has applied such a request from every connected robot
(in one batched write: :class:`simulator.api.batch.StepBatch`), the server arms a
:class:`TargetBoard`: one array of every robot's targets in the order of that write. From then on
whoever reads the requests (the I/O thread in async and pipelined stepping, the step thread while
it waits in plain lockstep) writes each usual request's values into its robot's span
(:meth:`BoardSlot.post`) instead of queueing it, and the step thread writes the spans posted since
the last step in one call (:meth:`TargetBoard.apply`) without looking at any session or
connection queue: with the I/O thread the Python work, and the memory it touches between two
physics steps, of one robot's request is gone from the step thread; without it what is left per
robot is the span's write as the request is read.

Anything else ends the board (:meth:`TargetBoard.end`) before the step's requests are applied
robot by robot: a request of another kind or name list (queued as before and counted in
``events``: every later request of that client is queued behind it), a client connecting,
leaving or failing, a robot made limp, released or removed. Ending gives back what the board
held, so that the robot-by-robot path goes on exactly as if there had been no board:

- each span posted since the last write goes back to the front of its connection's queue as the
  request it came from;
- each session holds the targets last written for it (:meth:`RobotSession.hold_targets`), as
  :meth:`RobotSession.take_targets` would have left them (they are re-applied when a penalised
  robot is released).

A span not posted since the last step is not written again (a robot whose client sent nothing
keeps whatever the world gave its motors meanwhile). One lock, shared by the server's
connections (``Connection.requests_lock``), orders the I/O thread's posts and queueing with the
step thread's arming, writing and ending.
"""

from __future__ import annotations

import threading
from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np
import numpy.typing as npt

from contracts.robot_api import messages_pb2 as pb
from simulator.api.fastreq import Notice, PositionTargets, TargetValues
from simulator.api.session import RobotSession, TargetPlan

if TYPE_CHECKING:
    from simulator.api.batch import StepBatch
    from simulator.api.connection import Connection

Request = pb.ActuatorRequests | PositionTargets | Notice


class BoardSlot:
    """One robot's span ``[start, end)`` of a :class:`TargetBoard`, for the targets of
    ``names`` (the name list its session holds)."""

    __slots__ = ("board", "index", "start", "end", "names", "plan", "conn", "session")

    def __init__(
        self,
        board: TargetBoard,
        index: int,
        start: int,
        plan: TargetPlan,
        conn: Connection,
        session: RobotSession,
    ) -> None:
        self.board = board
        self.index = index
        self.start = start
        self.end = start + len(plan.names)
        self.names = plan.names
        self.plan = plan
        self.conn = conn
        self.session = session

    def post_values(self, names: tuple[str, ...], values: Sequence[float]) -> bool:
        """The reader, under the lock, with nothing queued on the connection: one usual
        request's finite ``values`` for ``names`` onto the board (what :meth:`post` does with a
        :class:`PositionTargets` of them, without making one); False when ``names`` is not the
        list of this span (the caller queues the request the usual way)."""
        if names is not self.names:
            return False
        board = self.board
        board.values[self.start : self.end] = values
        board.fresh[self.index] = True
        return True

    def post(self, decoded: Sequence[Request], queue: list[Request]) -> None:
        """The reader (the I/O thread, or the step thread without it), under the lock: each
        usual request of ``decoded`` (in order) onto the board while the connection's ``queue``
        is empty; any other request, and everything after it, into ``queue`` (the board ends at
        the next step)."""
        board = self.board
        for request in decoded:
            if (
                not queue
                and type(request) is PositionTargets
                and request.names is self.names
                and request.finite
            ):
                board.values[self.start : self.end] = request.values
                board.fresh[self.index] = True
            else:
                queue.append(request)
                board.events += 1


class TargetBoard:
    """The usual targets of the robots of one batched write (see the module's text)."""

    __slots__ = ("slots", "conns", "values", "applied", "fresh", "events", "connection_changes",
                 "removed", "_write_all", "_batch")  # fmt: skip

    def __init__(
        self,
        robots: Sequence[tuple[Connection, RobotSession, TargetPlan, TargetValues]],
        batch: StepBatch,
        *,
        connection_changes: int,
        removed: list[bool],
    ) -> None:
        """``robots``: each connection, its session, and the plan and values of the batched
        write that armed the board (in its order); ``connection_changes`` and ``removed``: the
        server's count of clients welcomed and dropped and the world's removed flags then (any
        change ends the board)."""
        self.slots: list[BoardSlot] = []
        start = 0
        for index, (conn, session, plan, _) in enumerate(robots):
            self.slots.append(BoardSlot(self, index, start, plan, conn, session))
            start += len(plan.names)
        self.conns = tuple([slot.conn for slot in self.slots])
        # what the I/O thread posted (written at the next step), and what was written last
        self.values: npt.NDArray[np.float64] = np.concatenate(
            [np.asarray(values, dtype=np.float64) for _, _, _, values in robots]
        )
        self.applied = self.values.copy()
        self.fresh = [False] * len(self.slots)  # posted since the last write, per slot
        self.events = 0  # requests queued instead of posted
        self.connection_changes = connection_changes
        self.removed = removed
        self._batch = batch
        self._write_all = batch.targets_writer(tuple([plan for _, _, plan, _ in robots]))

    def attach(self, lock: threading.Lock) -> bool:
        """Step thread: route the connections' usual requests to the board; False (nothing
        attached) when a connection has requests queued (they apply robot by robot first)."""
        with lock:
            if any(conn.requests for conn in self.conns):
                return False
            for slot in self.slots:
                slot.conn.board = slot
        return True

    def apply(self, lock: threading.Lock) -> bool:
        """Step thread, before the step: write the spans posted since the last call. False
        (nothing written) when a request was queued meanwhile: the board must end."""
        with lock:
            if self.events:
                return False
            fresh = self.fresh
            if True not in fresh:
                return True
            self.fresh = [False] * len(fresh)
            whole = False not in fresh  # every robot posted: one write of the whole board
            if whole:
                self.applied = values = self.values.copy()
            else:
                posted = [slot for slot, new in zip(self.slots, fresh, strict=True) if new]
                for slot in posted:
                    self.applied[slot.start : slot.end] = self.values[slot.start : slot.end]
        if whole:
            self._write_all(values, finite=True)
        else:
            applied = self.applied
            self._batch.set_targets([(slot.plan, applied[slot.start : slot.end])
                                     for slot in posted])  # fmt: skip
        return True

    def end(self, lock: threading.Lock) -> None:
        """Step thread: detach the connections and give back what the board holds (the
        module's text): the spans posted since the last write to the front of their queues,
        and to each session the targets written last."""
        with lock:
            for slot, new in zip(self.slots, self.fresh, strict=True):
                conn = slot.conn
                conn.board = None
                if new:
                    values = self.values[slot.start : slot.end].copy()
                    conn.requests.insert(0, PositionTargets(slot.names, values, finite=True))
                slot.session.hold_targets(slot.names, self.applied[slot.start : slot.end])
            self.fresh = [False] * len(self.slots)
