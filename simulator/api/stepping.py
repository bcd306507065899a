"""The stepping policies: how each basic step meets the robots' requests and measurements.

Every policy has the same small surface, which the match loop (and ``hlvs bench api``) calls
around each step::

    stepping.before_step(world.sim_time_ms, world.sim_time_ms + world.step_ms)
    world.step()
    stepping.after_step(world.sim_time_ms)  # then the referee looks at the step

While the referee waits for wall-clock time (before the first READY, between periods) or the
game is over, a policy that :attr:`~Stepping.holds` stops stepping and the loop calls
:meth:`~Stepping.hold` instead; :meth:`~Stepping.end` after the last step.

* :class:`AsyncStepping`: the requests that arrived are applied, the step's measurement goes
  out; nobody is waited for, and the match never holds (as in the league).
* :class:`LockstepStepping`: before each step, one answer from every connected, non-slow
  client (:func:`simulator.api.lockstep.wait_lockstep`); while held, each client gets one
  measurement of the held time telling why (:func:`hold_text`).
* :class:`PipelinedStepping`: lockstep, one step late: the answers awaited are those to the
  measurement sent before the step just computed, so the clients think while the next step
  is computed, and their actions apply one step later than in lockstep (a fixed latency:
  still deterministic).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Protocol

from contracts import RobotId
from simulator.api.lockstep import wait_lockstep
from simulator.api.server import ApiServer, LockstepSettings, Request

STEPPINGS = ("async", "lockstep", "pipelined")


def hold_text(sim_time_ms: int) -> str:
    """The warning a lockstep client gets while the match holds for a wall-clock wait."""
    return (
        f"lockstep: simulated time holds at {sim_time_ms} ms while the referee waits for "
        "wall-clock time (before the first READY, between periods); the next measurement "
        "comes with the next step. The wait is not simulated so that the match replays "
        "identically (its steps would depend on machine speed and connection times); "
        "async stepping keeps stepping during the wait, as in the league."
    )


class Stepping(Protocol):
    holds: bool  # steps stop while the referee waits for wall-clock time and after the game
    waited_s: float  # total time spent waiting for the clients

    def before_step(self, time_ms: int, step_time_ms: int) -> None:
        """Right before the step from ``time_ms`` to ``step_time_ms``: the requests it
        applies."""
        ...

    def after_step(self, time_ms: int) -> None:
        """The step that ended at ``time_ms`` (the referee's commands applied)."""
        ...

    def hold(self, time_ms: int, *, finished: bool) -> None:
        """One turn of a hold at ``time_ms`` (``finished``: the game is over)."""
        ...

    def end(self, time_ms: int) -> None:
        """The loop ended (not stopped) after the step that ended at ``time_ms``."""
        ...


class AsyncStepping:
    holds = False

    def __init__(self, server: ApiServer) -> None:
        self._server = server
        self.waited_s = 0.0

    def before_step(self, time_ms: int, step_time_ms: int) -> None:
        self._server.apply_requests(step_time_ms)

    def after_step(self, time_ms: int) -> None:
        self._server.publish(time_ms)

    def hold(self, time_ms: int, *, finished: bool) -> None:
        return None

    def end(self, time_ms: int) -> None:
        return None


class LockstepStepping:
    """``prefetch`` (the world's :meth:`~simulator.world.World.prefetch`): called as the wait
    for the answers begins, so that the next step's first position stage is computed
    meanwhile on a worker thread. Without it, while the server's exchange thread sends the
    step's measurements and reads the answers (:mod:`simulator.api.exchange`), the step thread
    computes that stage itself (:meth:`ApiServer.overlap`)."""

    holds = True

    def __init__(self, server: ApiServer, settings: LockstepSettings,
                 prefetch: Callable[[], None] | None = None) -> None:
        self._server = server
        self._settings = settings
        self._prefetch = prefetch
        self.waited_s = 0.0

    def before_step(self, time_ms: int, step_time_ms: int) -> None:
        if self._prefetch is not None:
            self._prefetch()
        elif self._server.exchanging:  # its thread sends and reads meanwhile
            self._server.overlap()
        self.waited_s += wait_lockstep(self._server, self._settings)
        self._server.apply_requests(step_time_ms)

    def after_step(self, time_ms: int) -> None:
        self._server.publish(time_ms)

    def hold(self, time_ms: int, *, finished: bool) -> None:
        """Each client connected during the hold gets one measurement of the held time with
        :func:`hold_text` (none once the game is over)."""
        if not finished:
            self._server.hold_notice(time_ms, hold_text(time_ms))

    def end(self, time_ms: int) -> None:
        return None


class PipelinedStepping:
    """Pipelined lockstep: :meth:`before_step` sends the measurement of step N only after
    waiting for and taking the answers to the measurement of step N-1, then applies those: no
    answer to step N can be among them whatever the timing, and the answers to step N apply at
    step N+2 (lockstep: N+1). Right before a step the answers are taken and applied in one pass
    (:meth:`ApiServer.apply_requests`, before the measurement goes out: nothing can have
    answered it yet); a send during a hold keeps them for the next step. No prefetch (as
    :class:`LockstepStepping` has): its wait is short, and the worker took the CPU its clients
    think on during the step (README, performance)."""

    holds = True

    def __init__(self, server: ApiServer, settings: LockstepSettings) -> None:
        self._server = server
        self._settings = settings
        self._taken: dict[RobotId, list[Request]] = {}
        self.unsent = False  # the latest step's measurement is not sent yet
        self.waited_s = 0.0

    def send(self, time_ms: int, step_time_ms: int | None = None) -> None:
        """Wait for the answers to the measurement sent last, take them, send the latest one
        (read and encoded before the wait: the world does not change until it is sent). With
        ``step_time_ms`` (right before that step) the answers are applied at once."""
        server = self._server
        prepared = server.prepare(time_ms)
        self.waited_s += wait_lockstep(server, self._settings)
        if step_time_ms is not None and not self._taken:
            server.apply_requests(step_time_ms)  # takes what arrived and applies it
        else:
            for robot, requests in server.take_requests().items():
                self._taken.setdefault(robot, []).extend(requests)
        server.publish_prepared(prepared)
        self.unsent = False

    def before_step(self, time_ms: int, step_time_ms: int) -> None:
        if self.unsent:
            self.send(time_ms, step_time_ms)  # applies the answers unless some were kept
            if not self._taken:
                return
        taken, self._taken = self._taken, {}
        self._server.apply_taken(taken, step_time_ms)

    def after_step(self, time_ms: int) -> None:
        self.unsent = True

    def hold(self, time_ms: int, *, finished: bool) -> None:
        """The held step's measurement goes out (the state the clients wait in), once."""
        if self.unsent:
            self.send(time_ms)

    def end(self, time_ms: int) -> None:
        """The last step's measurement goes out, as in lockstep."""
        if self.unsent:
            self._server.publish(time_ms)


def stepping_for(mode: str, server: ApiServer, settings: LockstepSettings,
                 prefetch: Callable[[], None] | None = None) -> Stepping:
    """The policy of ``mode`` (one of :data:`STEPPINGS`); ``prefetch``: the world's
    :meth:`~simulator.world.World.prefetch`, used by lockstep."""
    if mode == "pipelined":
        return PipelinedStepping(server, settings)
    if mode == "lockstep":
        return LockstepStepping(server, settings, prefetch)
    if mode == "async":
        return AsyncStepping(server)
    raise ValueError(f"stepping {mode!r}: expected one of {', '.join(STEPPINGS)}")
