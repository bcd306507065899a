"""The measurements of one step as the server prepares them (:class:`Prepared`), and the steady
form of a step (:class:`SteadyStep`): while every connected robot's measurement is its steady
session's (:attr:`RobotSession.steady`), all due at the same steps, the server builds a step
without asking each session (one gather, one plain measurement per robot)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from simulator.api.batch import Encoding, Gathered, StepBatch
from simulator.api.connection import Connection
from simulator.api.measurement import DuePlan, Measurement, header_bytes
from simulator.api.slots import RobotSlot


@dataclass(frozen=True, slots=True)
class SteadyStep:
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

    def holds(
        self,
        time_ms: int,
        *,
        connection_changes: int,
        steady_changes: int,
        removed: list[bool] | None,
    ) -> bool:
        """This form holds for the step that ended at ``time_ms``: due by it, the same
        clients, no robot removed, no session's steady state changed."""
        return (
            time_ms % self.period == self.phase
            and self.connection_changes == connection_changes
            and self.steady_changes == steady_changes
            and removed is not None
            and True not in removed
        )


def steady_form(
    prepared: list[tuple[RobotSlot, Measurement]],
    batched: list[tuple[Measurement, DuePlan]],
    encoding: Encoding,
    *,
    connection_changes: int,
    steady_changes: int,
) -> SteadyStep | None:
    """The :class:`SteadyStep` of a step built robot by robot (``batched``, gathered with
    ``encoding``), or None when some robot was not steady, due at other steps than the others
    or still owed a camera image."""
    if len(batched) != len(prepared):
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
    return SteadyStep(
        connection_changes=connection_changes,
        steady_changes=steady_changes,
        slots=tuple([slot for slot, _ in prepared]),
        conns=tuple(conns),
        plans=tuple([plan for _, plan in batched]),
        period=period,
        phase=phase,
        encoding=encoding,
    )


@dataclass(slots=True)
class SteadyValues:
    """One step's sensor values gathered by a :class:`SteadyStep`, not yet wire bytes (the
    head of the step's time is written with them, on the I/O thread)."""

    step: SteadyStep
    values: npt.NDArray[np.float64]
    time_ms: int
    real_time: int

    def frames(self, batch: StepBatch) -> list[bytes]:
        """Every robot's framed plain measurement of the step."""
        head = header_bytes(self.time_ms, self.real_time)
        return self.step.encoding_for(batch, head).frames(self.values, head)

    def frames_in_place(self, batch: StepBatch) -> tuple[memoryview, tuple[tuple[int, int], ...]]:
        """:meth:`frames` as one view of a buffer the encoding reuses every step, and each
        robot's frame's span in it (:meth:`~simulator.api.batch.Encoding.frames_in_place`)."""
        head = header_bytes(self.time_ms, self.real_time)
        encoding = self.step.encoding_for(batch, head)
        return encoding.frames_in_place(self.values, head), encoding.frames_at

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
    steady: SteadyValues | None = None
