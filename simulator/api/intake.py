"""The clients' requests applied to the world, before each physics step.

:class:`Intake` takes what each connected client sent and applies it in arrival order (later
targets override earlier ones): the usual requests of every robot (the motor names of its
previous one, robot active) in one batched write (:class:`~simulator.api.batch.StepBatch`), the
others robot by robot. Once a step applied the usual request of every connected robot, the
target board is armed (:mod:`simulator.api.board`): whoever reads the requests (the I/O thread,
or the step thread in plain lockstep) posts the targets there and a step applies them with one
write, until something ends it (a client
comes or goes or fails, a robot is made limp, released or removed). Pipelined stepping detaches
the requests first (:meth:`Intake.take`) and applies them a step later
(:meth:`Intake.apply_taken`).
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import NamedTuple

from contracts import RobotId
from simulator.api.batch import StepBatch
from simulator.api.board import TargetBoard
from simulator.api.connection import Connection
from simulator.api.fastreq import TargetValues
from simulator.api.ports import Ports
from simulator.api.session import RobotSession, TargetPlan
from simulator.api.slots import Request, RobotSlot


class EveryUsual(NamedTuple):
    """A step's requests when every connected robot sent its usual one: the connections, their
    sessions and the targets written (in one order), from which the target board is armed."""

    connections: list[Connection]
    sessions: list[RobotSession]
    usual: list[tuple[TargetPlan, TargetValues]]


class Intake:
    """Applies the clients' requests of the slots served by ``ports``. ``limp_flags`` and
    ``removed_flags``: the world's flags (lists it changes in place), when it has them."""

    def __init__(
        self,
        *,
        slots: Mapping[RobotId, RobotSlot],
        ports: Ports,
        batch: StepBatch | None,
        limp_flags: list[bool] | None,
        removed_flags: list[bool] | None,
    ) -> None:
        self._slots = slots
        self._ports = ports
        self._batch = batch
        self._limp_flags = limp_flags
        self._limp_seen: list[bool] | None = None  # the limp flags as the sessions last saw them
        self._removed_flags = removed_flags
        self._board: TargetBoard | None = None

    def apply_received(self, step_time_ms: int) -> EveryUsual | None:
        """Apply every received request in arrival order. While the target board is armed
        that is one write of what the I/O thread posted on it. The requests when every
        connected robot sent its usual one (see :meth:`arm_board`), else None."""
        board = self._board
        if board is not None:
            if self._board_holds(board) and board.apply(self._ports.requests_lock):
                return None
            self.end_board()
        self._update_limps()
        received: list[tuple[RobotSession, list[Request]]] = []
        connections: list[Connection] = []
        for slot in self._slots.values():
            session = slot.session
            conn = slot.conn
            if conn is None:
                continue
            connections.append(conn)
            if conn.threaded:
                if conn.error is not None:  # found by the I/O thread
                    self._ports.drop(slot, conn.error)
                    continue
                if conn.requests:
                    received.append((session, conn.take_requests()))
            elif conn.requests:
                received.append((session, conn.requests))
                conn.requests = []
        usual = self._apply(received, step_time_ms)
        if usual and len(usual) == len(connections) and self._limp_flags is not None:
            return EveryUsual(connections, [session for session, _ in received], usual)
        return None

    def _board_holds(self, board: TargetBoard) -> bool:
        """Nothing that ends the target board happened since it was armed: the same clients,
        none failed, no robot made limp, released or removed (the requests it queued are
        counted by :meth:`TargetBoard.apply`)."""
        if board.connection_changes != self._ports.connection_changes:
            return False
        if self._limp_flags != self._limp_seen:
            return False
        if self._removed_flags != board.removed:
            return False
        for conn in board.conns:
            if conn.error is not None:
                return False
        return True

    def arm_board(self, every: EveryUsual) -> None:
        """Arm the target board after a step that wrote every connected robot's usual
        targets (with the world's limp and removed flags)."""
        if self._batch is None or self._removed_flags is None:
            return
        board = TargetBoard(
            [(conn, session, plan, values)
             for conn, session, (plan, values) in zip(
                 every.connections, every.sessions, every.usual, strict=True)],
            self._batch,
            connection_changes=self._ports.connection_changes,
            removed=list(self._removed_flags),
        )  # fmt: skip
        if board.attach(self._ports.requests_lock):
            self._board = board

    def end_board(self) -> None:
        """End the target board, if armed: the robot-by-robot path goes on from what it
        held (:meth:`TargetBoard.end`)."""
        board = self._board
        if board is not None:
            self._board = None
            board.end(self._ports.requests_lock)

    def _update_limps(self) -> None:
        """Every session follows the world's limp flags (:meth:`RobotSession.update_limp`);
        one comparison with the flags seen last when the world has them in a list."""
        limp = self._limp_flags
        if limp is not None and limp == self._limp_seen:
            return
        for slot in self._slots.values():
            slot.session.update_limp()
        if limp is not None:
            self._limp_seen = list(limp)

    def take(self) -> dict[RobotId, list[Request]]:
        """Pipelined stepping: detach every client's received requests, to be applied later
        by :meth:`apply_taken`."""
        self.end_board()
        taken: dict[RobotId, list[Request]] = {}
        for robot, slot in self._slots.items():
            conn = slot.conn
            if conn is None:
                continue
            if conn.threaded and conn.error is not None:  # found by the I/O thread
                self._ports.drop(slot, conn.error)
                continue
            if conn.requests:
                taken[robot] = conn.take_requests()
        return taken

    def apply_taken(self, taken: dict[RobotId, list[Request]], step_time_ms: int) -> None:
        """Pipelined stepping: apply requests detached by :meth:`take` in arrival order (a
        robot's requests apply even when its client left since)."""
        self.end_board()
        self._update_limps()
        slots = self._slots
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
