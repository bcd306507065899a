"""The step's measurements sent out: framed, counted in each robot's quota and queued on its
client, after each physics step.

:class:`Outbox` queues what :meth:`ApiServer.prepare` built. Without the I/O thread it frames
each measurement here and writes what the sockets take (``blocking_send``: waits until they took
everything, the HLVS behaviour). With it the step thread hands the step over
(:meth:`Outbox.flush`) and the I/O thread writes the wire bytes, frames and queues them
(:meth:`Outbox._deliver`; a steady step's values framed for every robot at once:
:meth:`Outbox._deliver_steady`). A measurement with a camera waits for its images (and the
robot's later ones behind it) and goes out when the render worker gives them back
(:meth:`Outbox.camera_results`).
"""

from __future__ import annotations

import time
from collections.abc import Callable, Mapping
from functools import partial

from contracts import NetworkSpec, RobotId
from contracts.robot_api import messages_pb2 as pb
from simulator.api.batch import Gathered, StepBatch
from simulator.api.cameras import MAX_IN_FLIGHT, ImageSource
from simulator.api.connection import ClientClosed, Connection, sent_elsewhere
from simulator.api.exchange import Exchange
from simulator.api.framing import HEADER
from simulator.api.measurement import Measurement
from simulator.api.ports import Ports
from simulator.api.session import ERROR, WARNING
from simulator.api.slots import IoThreadFailed, Pending, RobotSlot
from simulator.api.steady import Prepared, SteadyValues


class Outbox:
    """Sends the measurements of the slots served by ``ports``."""

    def __init__(
        self,
        *,
        slots: Mapping[RobotId, RobotSlot],
        ports: Ports,
        network: NetworkSpec,
        lockstep: bool,
        batch: StepBatch | None,
        cameras: ImageSource | None,
        unix_ms: Callable[[], int],
    ) -> None:
        self._slots = slots
        self._ports = ports
        self._blocking = network.blocking_send
        self._lockstep = lockstep
        self._batch = batch
        self._cameras = cameras
        self._unix_ms = unix_ms
        # with the I/O thread: this step's measurements to frame and queue there, in order
        self._outgoing: list[tuple[RobotSlot, Connection, Measurement]] = []
        self._unwritten: Gathered | None = None
        self._sent_at = 0.0
        self._hold_told: set[tuple[int, int]] = set()  # (connection id, held sim time) told

    def hold_notice(self, time_ms: int, text: str) -> int:
        """See :meth:`ApiServer.hold_notice`."""
        self._ports.count_owed()
        real_time = self._unix_ms()
        now = time.monotonic()
        told = 0
        for slot in self._slots.values():
            conn = slot.conn
            if conn is None or (id(conn), time_ms) in self._hold_told:
                continue
            self._hold_told.add((id(conn), time_ms))
            notice = Measurement(time_ms, real_time)
            notice.header.messages.add(message_type=WARNING, text=text)
            self._send(slot, conn, notice, now)
            told += 1
        if told:
            self.flush()
        return told

    def publish(self, prepared: Prepared) -> None:
        """Queue measurements made by :meth:`ApiServer.prepare` (a client dropped meanwhile
        gets none)."""
        self._ports.settle(0.0)  # (plain lockstep: the exchange's last step is over)
        steady = prepared.steady
        if steady is not None:
            if steady.step.connection_changes == self._ports.connection_changes:
                if self._ports.sender is not None:
                    self._publish_steady(steady)
                    return
                if not self._blocking:
                    self._send_steady(steady)
                    return
            # blocking sends, or a client left since: robot by robot
            assert self._batch is not None  # (a steady step is only recorded with the batch)
            prepared = Prepared(steady.measurements(self._batch))
        self._ports.count_owed()
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
                slot.pending.append(Pending(measurement, len(jobs)))
                self._ports.maybe_waiting = True
            else:
                self._send(slot, conn, measurement, now)
        self._unwritten = unwritten
        if jobs_all:
            assert self._cameras is not None, "camera enabled without a render worker"
            self._cameras.submit(jobs_all)
            while self._cameras.in_flight > MAX_IN_FLIGHT and not self._ports.stop_requested:
                self._ports.poll(0.05)  # rendering is behind: let it catch up (results end it)
        self.flush()

    def _publish_steady(self, steady: SteadyValues) -> None:
        """Hand a steady step's values to the I/O thread, which frames and queues them for
        every robot (:meth:`_deliver_steady`): what the step thread does per robot is the
        lockstep flag."""
        sender = self._ports.sender
        assert sender is not None
        if self._lockstep:  # (the flag lockstep waits on; async never waits)
            for conn in steady.step.conns:
                conn.owe()
        self.flush()  # anything queued before, in order
        sender.submit(partial(self._deliver_steady, steady, time.monotonic()))

    def _send_steady(self, steady: SteadyValues) -> None:
        """Without the I/O thread (plain lockstep): a steady step's frames written for every
        robot at once, into a buffer kept from step to step, and each robot's sent straight
        from it (a view, no copy: :meth:`Connection.send` copies what the socket does not
        take), counted in its robot's quota, without a measurement per robot (what
        :meth:`_deliver_steady` does on the I/O thread). Only a client whose socket did not
        take its frame is flushed again."""
        assert self._batch is not None
        step = steady.step
        real_time = steady.real_time
        now = time.monotonic()
        frames, spans = steady.frames_in_place(self._batch)
        admitted = 0
        exchange = self._ports.exchange
        if exchange is not None:
            admitted = self._exchange_steady(exchange, steady, frames, spans, now)
            if admitted < 0:
                return
            exchange.count_owed()
        behind: list[RobotSlot] = []
        for index, (slot, conn, (start, end)) in enumerate(
            zip(step.slots, step.conns, spans, strict=True)
        ):
            if index < admitted or slot.quota.admit(end - start - HEADER.size, real_time):
                frame = frames[start:end]
            else:
                frame = memoryview(self._quota_error(slot, steady.time_ms, real_time))
            try:
                conn.send(frame, now)
            except ClientClosed as exc:
                self._ports.drop(slot, exc.reason)
                continue
            if conn.want_write:
                behind.append(slot)
        for slot in behind:
            if slot.conn is not None:
                self._ports.flush(slot)

    def _exchange_steady(
        self, exchange: Exchange, steady: SteadyValues, frames: memoryview,
        spans: tuple[tuple[int, int], ...], now: float,
    ) -> int:
        """Plain lockstep with the exchange thread (:mod:`simulator.api.exchange`): hand it
        the step's frames when every frame is within its quota and :meth:`Exchange.begin`
        takes them; -1 when it did. Otherwise the number of robots whose frame the quota
        already admitted (sent here)."""
        step = steady.step
        real_time = steady.real_time
        admitted = 0
        for slot, (start, end) in zip(step.slots, spans, strict=True):
            if not slot.quota.admit(end - start - HEADER.size, real_time):
                return admitted
            admitted += 1
        if not exchange.begin(step.slots, step.conns, frames, spans):
            return admitted
        exchange.count_owed()  # the last exchange's, while this one is under way
        for conn in step.conns:
            sent_elsewhere(conn, now)
        return -1

    def _send(
        self, slot: RobotSlot, conn: Connection, measurement: Measurement, now: float
    ) -> None:
        if conn.threaded:  # framed and queued on the I/O thread (handed over by flush)
            self._outgoing.append((slot, conn, measurement))
            self._sent_at = now
            return
        frame = self._framed(slot, measurement)
        try:
            conn.send(frame, now)
        except ClientClosed as exc:
            self._ports.drop(slot, exc.reason)

    def _framed(self, slot: RobotSlot, measurement: Measurement) -> bytes:
        """The measurement's framed message, counted in the robot's quota, or the quota's
        ERROR message in its place."""
        frame = measurement.frame
        if frame is not None:  # built whole by the step's batch: no header, no message
            return self._admitted(slot, frame, measurement.time, measurement.real_time)
        head, sensors = measurement.head_parts(), measurement.sensors
        size = sum(map(len, head)) + len(sensors)
        if not slot.quota.admit(size, measurement.real_time):
            return self._quota_error(slot, measurement.time, measurement.real_time)
        warnings = measurement.message_count
        if warnings:
            slot.stats.warnings_sent += warnings
        return b"".join((HEADER.pack(size), *head, sensors))

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

    def flush(self) -> None:
        """Send what was queued: hand it to the I/O thread (raising its failure, if it
        stopped on one), or write what each socket takes."""
        sender = self._ports.sender
        if sender is not None:
            if sender.failure is not None:
                raise IoThreadFailed(sender.failure) from sender.failure
            if self._outgoing or self._unwritten is not None:
                sender.submit(partial(self._deliver, self._outgoing, self._unwritten,
                                      self._sent_at))  # fmt: skip
                self._outgoing = []
                self._unwritten = None
            return
        for slot in self._slots.values():
            if slot.conn is None or slot.conn.idle:
                continue
            self._ports.flush(slot)
            if self._blocking:
                self._ports.flush_blocking(slot)

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

    def _deliver_steady(self, steady: SteadyValues, now: float) -> list[Connection]:
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

    def camera_results(self) -> None:
        """Take the rendered images and send the measurements they completed, in order."""
        assert self._cameras is not None
        touched: set[RobotId] = set()
        for job, image in self._cameras.completed():
            slot = self._slots[job.robot]
            job.image = image
            for pending in slot.pending:
                if pending.measurement.time == job.time_ms and pending.missing:
                    pending.missing -= 1
                    break
            touched.add(job.robot)
        now = time.monotonic()
        for robot in touched:
            slot = self._slots[robot]
            while slot.pending and slot.pending[0].missing == 0 and slot.conn is not None:
                self._send(slot, slot.conn, slot.pending.popleft().measurement, now)
        self.flush()
