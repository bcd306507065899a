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

:class:`ApiServer` puts together the pieces, each over the same robot slots
(:mod:`simulator.api.slots`): the sockets (:class:`~simulator.api.ports.Ports`), the requests
applied to the world (:class:`~simulator.api.intake.Intake`), the step's measurements read
(here, with their steady form: :mod:`simulator.api.steady`) and sent
(:class:`~simulator.api.outbox.Outbox`); it decides when the step thread polls and keeps the
robots' statistics.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from functools import partial

from contracts import NetworkSpec, RobotApiStats, RobotId
from referee import SpoofingLog
from simulator.api.batch import Gathered, StepBatch
from simulator.api.cameras import ImageSource
from simulator.api.connection import AnswerBook, Connection
from simulator.api.devices import DeviceWorld
from simulator.api.endpoints import PlayerEndpoint
from simulator.api.exchange import wanted as exchanges_wanted
from simulator.api.intake import EveryUsual, Intake
from simulator.api.measurement import DuePlan, Measurement, header_bytes
from simulator.api.outbox import Outbox
from simulator.api.ports import Ports
from simulator.api.quota import NetworkQuota
from simulator.api.sender import SendThread
from simulator.api.session import RobotSession, SteadyChanges
from simulator.api.slots import (
    IoThreadFailed,
    LockstepSettings,
    PortUnavailable,
    Request,
    RobotSlot,
)
from simulator.api.stats import RobotStats
from simulator.api.steady import Prepared, SteadyStep, SteadyValues, steady_form

__all__ = [
    "ApiServer",
    "IoThreadFailed",
    "LockstepSettings",
    "PortUnavailable",
    "Prepared",
    "Request",
    "RobotSlot",
]

# With the I/O thread the step thread's own selector only accepts connections (and takes camera
# images): before a step it is polled when POLL_INTERVAL_S of wall time has passed since the last
# poll, and every step while a measurement waits for an image or a name lookup runs. A world that
# steps faster than real time makes no syscall on most steps (a select between two physics steps
# costs the step thread the select and the memory it touches); a client is still welcomed within
# that interval.
POLL_INTERVAL_S = 0.01


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
        exchange: bool | None = None,
    ) -> None:
        """``send_thread``: the clients' reads and writes on an I/O thread (default: in async
        and pipelined stepping without ``blocking_send``); ``send_cpus``: the CPUs that thread
        (or the exchange thread) may use; ``exchange``: plain lockstep's steady steps exchanged
        by a compiled thread (:mod:`simulator.api.exchange`; default: where it can run)."""
        # the per-step work over all robots at once, when the world has the batch forms
        self._batch = StepBatch(world) if StepBatch.supports(world) else None
        self._unix_ms = unix_ms
        if send_thread is None:
            send_thread = not network.blocking_send and (lockstep is None or lockstep.pipelined)
        self._next_poll = 0.0  # with the I/O thread: when the step thread polls its selector next
        # the steady form of the last step built robot by robot (None: not every robot steady)
        self._steady_step: SteadyStep | None = None
        # the world's removed flags (changed in place), when it has them: a removed robot's
        # measurement is not its steady one; and its limp flags
        flags = getattr(world, "robot_flags", None)
        world_flags = flags(endpoints[0].robot) if flags is not None and endpoints else None
        self._removed_flags: list[bool] | None = world_flags[1] if world_flags else None
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
        if exchange is None:
            exchange = exchanges_wanted(send_cpus)
        plain_lockstep = lockstep is not None and not send_thread and not network.blocking_send
        prefetch = getattr(world, "prefetch", None)
        self._ports = Ports(
            world=world, slots=self.slots, network=network, lockstep=lockstep,
            spoofing=spoofing or SpoofingLog(), send_thread=send_thread, send_cpus=send_cpus,
            exchange=exchange and plain_lockstep and self._batch is not None,
        )  # fmt: skip
        # the world's next first position stage, computed on the step thread while the
        # exchange thread works (:meth:`overlap`)
        self._stage: Callable[[], None] | None = (
            partial(prefetch, inline=True) if prefetch is not None else None
        )
        self._intake = Intake(
            slots=self.slots, ports=self._ports, batch=self._batch,
            limp_flags=world_flags[0] if world_flags else None,
            removed_flags=self._removed_flags,
        )  # fmt: skip
        self._outbox = Outbox(
            slots=self.slots, ports=self._ports, network=network,
            lockstep=lockstep is not None, batch=self._batch, cameras=cameras, unix_ms=unix_ms,
        )  # fmt: skip
        if cameras is not None:
            self._ports.add_reader(cameras.wake_fd, self._outbox.camera_results)

    # --- lifecycle --------------------------------------------------------------------------

    def start(self) -> None:
        self._ports.start()

    def close(self) -> None:
        self._ports.close()

    def __enter__(self) -> ApiServer:
        self.start()
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    # --- state shared with the stepping loop (simulator.api.lockstep, simulator.match_loop) --

    @property
    def answers(self) -> AnswerBook | None:
        """Lockstep: who owes an answer and who is slow (None in async stepping)."""
        return self._ports.answers

    @property
    def stop_requested(self) -> bool:
        """Set to end every wait of the server (camera back-pressure, blocking sends)."""
        return self._ports.stop_requested

    @stop_requested.setter
    def stop_requested(self, value: bool) -> None:
        self._ports.stop_requested = value

    @property
    def awaiting_answers(self) -> bool:
        """Set while the step thread waits for answers: the I/O thread then wakes its poll."""
        return self._ports.awaiting_answers

    @awaiting_answers.setter
    def awaiting_answers(self, value: bool) -> None:
        self._ports.awaiting_answers = value

    @property
    def exchanging(self) -> bool:
        """Plain lockstep's exchange thread is sending this step's measurements and reading
        the answers (:mod:`simulator.api.exchange`)."""
        exchange = self._ports.exchange
        return exchange is not None and exchange.run is not None

    def overlap(self) -> None:
        """While :attr:`exchanging`: compute the world's next first position stage on this
        thread (:meth:`World.prefetch` inline), which needs no answer."""
        if self._stage is not None:
            self._stage()

    def settle_exchange(self, wait_s: float) -> bool:
        """End the exchange in flight (its thread reads answers for ``wait_s`` at most): what
        it did not take is read here (:func:`simulator.api.exchange.settle`). True when there
        was one and it took every client's answer (lockstep has nobody left to wait for)."""
        if not self.exchanging:
            return False
        self._ports.settle(wait_s)
        return self._ports.exchange is not None and self._ports.exchange.clean

    @property
    def exchange_figures(self) -> dict[str, int] | None:
        """The exchange thread's steps, the answers it took and those it handed back (None
        without it)."""
        exchange = self._ports.exchange
        if exchange is None:
            return None
        return {"steps": exchange.steps, "taken": exchange.taken,
                "handed_back": exchange.handed_back}  # fmt: skip

    @property
    def connection_changes(self) -> int:
        """Clients welcomed or dropped so far."""
        return self._ports.connection_changes

    @property
    def _sender(self) -> SendThread | None:
        """The I/O thread, while started with one."""
        return self._ports.sender

    # --- queries ----------------------------------------------------------------------------

    def connected(self) -> list[str]:
        return [slot.session.key for slot in self.slots.values() if slot.conn is not None]

    def traffic(self) -> dict[str, tuple[bool, RobotStats]]:
        """Each robot's live counters and whether it is connected (cheap: nothing copied;
        with the exchange thread they may be a step behind)."""
        return {s.session.key: (s.conn is not None, s.stats) for s in self.slots.values()}

    def statistics(self) -> dict[str, RobotApiStats]:
        self._ports.count_owed()
        return {slot.session.key: slot.stats.to_dict() for slot in self.slots.values()}

    @property
    def io_wakes(self) -> int:
        """Wake-ups of the I/O thread the step thread has paid for so far (a write to its pipe
        each: :mod:`simulator.api.sender`); 0 without the thread."""
        sender = self._ports.sender
        return sender.wakes if sender is not None else 0

    def connection(self, robot: RobotId) -> Connection | None:
        return self.slots[robot].conn

    # --- I/O --------------------------------------------------------------------------------

    def poll(self, timeout_s: float = 0.0) -> None:
        """Serve sockets: accept, handshake, read requests, write queued measurements (with
        the I/O thread: drop the clients it found failed); take camera results."""
        self._ports.poll(timeout_s)

    def _poll_before_step(self) -> None:
        """Serve the sockets before a step: every step without a thread that reads them; with
        the I/O thread, or after an exchange that took every answer, every
        :data:`POLL_INTERVAL_S` (or while something waits for a camera or a name lookup)."""
        exchange = self._ports.exchange
        if self._ports.sender is not None or (exchange is not None and exchange.clean):
            now = time.monotonic()
            if now < self._next_poll and not (self._ports.maybe_waiting and self._waiting()):
                return
            self._next_poll = now + POLL_INTERVAL_S
        self._ports.poll(0.0)

    def _waiting(self) -> bool:
        """Some measurement waits for a camera image, or some client for its name lookup (then
        the step thread polls every step); clears ``maybe_waiting`` when none does."""
        if any(slot.pending or slot.checking for slot in self.slots.values()):
            return True
        self._ports.maybe_waiting = False
        return False

    # --- the step: requests in --------------------------------------------------------------

    def apply_requests(self, step_time_ms: int) -> None:
        """Read what is available, then apply every received request in arrival order.
        While the target board is armed that is one write of what the reader posted on it
        (:mod:`simulator.api.board`); a step that applies the usual request of every connected
        robot arms it."""
        self._poll_before_step()
        every = self._intake.apply_received(step_time_ms)
        if every is not None:
            self._arm_board(every)

    def _arm_board(self, every: EveryUsual) -> None:
        self._intake.arm_board(every)

    def take_requests(self) -> dict[RobotId, list[Request]]:
        """Pipelined stepping: read what is available and detach every client's received
        requests, to be applied later by :meth:`apply_taken` (the step after next)."""
        self._poll_before_step()
        return self._intake.take()

    def apply_taken(self, taken: dict[RobotId, list[Request]], step_time_ms: int) -> None:
        """Pipelined stepping: apply requests detached by :meth:`take_requests` in arrival
        order (a robot's requests apply even when its client left since)."""
        self._intake.apply_taken(taken, step_time_ms)

    # --- the step: measurements out ---------------------------------------------------------

    def hold_notice(self, time_ms: int, text: str) -> int:
        """While the lockstep loop holds at ``time_ms`` (the referee waits for wall-clock time):
        each connected client not told yet during this hold gets one measurement of that time
        with ``text`` as a warning and no sensors; nothing else reaches it until the next step.
        The world is not touched: a notice changes nothing that is simulated. Returns the
        number of clients told now."""
        return self._outbox.hold_notice(time_ms, text)

    def publish(self, time_ms: int) -> None:
        """Queue the measurement of the step that ended at ``time_ms`` for every client."""
        self.publish_prepared(self.prepare(time_ms))

    def prepare(self, time_ms: int) -> Prepared:
        """The measurements of the step that ended at ``time_ms`` for the connected clients,
        read but not queued: :meth:`publish_prepared` queues them. Pipelined stepping builds
        them before it waits for the answers to the previous ones. Without the I/O thread they
        are encoded here; with it the wire bytes are written there (``unwritten``, or
        ``steady`` when every robot is steady: see :class:`~simulator.api.steady.SteadyStep`;
        then the step thread only reads the values)."""
        real_time = self._unix_ms()  # one instant for the whole step
        steady = self._steady_step
        if steady is not None and steady.holds(
            time_ms,
            connection_changes=self._ports.connection_changes,
            steady_changes=self._steady_changes.count,
            removed=self._removed_flags,
        ):
            values = steady.encoding.gather()
            return Prepared([], steady=SteadyValues(steady, values, time_ms, real_time))
        items, gathered = self._prepare_each(time_ms, real_time)
        if gathered is not None and self._ports.sender is None:
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
        self._steady_step = (
            steady_form(
                prepared, batched, gathered.encoding,
                connection_changes=self._ports.connection_changes,
                steady_changes=self._steady_changes.count,
            )  # fmt: skip
            if self._removed_flags is not None
            else None
        )
        return prepared, gathered

    def publish_prepared(self, prepared: Prepared) -> None:
        """Queue measurements made by :meth:`prepare` (a client dropped meanwhile gets none)."""
        self._outbox.publish(prepared)
