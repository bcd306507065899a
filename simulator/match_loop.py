"""The simulator's step loop: requests -> physics -> referee -> measurements -> record.

One basic step (8 ms of simulated time)::

    [lockstep: wait for one request per client]  ->  apply requests  ->  world.step()
    -> snapshot -> referee.step -> apply its commands -> publish measurements
    -> recorder / telemetry -> pacing (async: maximum_real_time_factor)

Pipelined lockstep overlaps the physics with the robots' thinking, at the price of one step of
action latency (fixed, so the match stays deterministic)::

    wait for one request per client (the answers to the measurement sent before this step)
    -> take them -> send the measurement of step N -> apply the taken requests
    -> world.step() (step N+1, while the clients compute their answers to step N) -> referee

so the actions a robot sends while step N+1 is computed apply at step N+2 (in lockstep they
apply at step N+1). Nothing of step N reaches a client before the answers to step N-1 are
taken, so which requests a step applies never depends on timing.

While the referee waits for wall-clock time (before the first READY, between halves) an async
match keeps stepping, as in HLVS; a lockstep (or pipelined) match holds (no steps, connections
still served) so its result does not depend on machine speed: the number of steps in a wall-clock
wait, and the step at which each robot connects within it, would depend on how fast the machine
and the robots are, and so would every simulated time and pose after it. A client connected
while a plain lockstep match holds gets one measurement of the held time with a warning that
says so (:func:`simulator.api.stepping.hold_text`); a pipelined match sends it the held
step's measurement. How a step meets the clients is the stepping policy's
(:mod:`simulator.api.stepping`).
"""

from __future__ import annotations

import logging
import struct
import time
from dataclasses import dataclass
from typing import Any, Protocol

import numpy as np

from contracts import EventRecord, GameStateRecord, StateMessage
from referee import RefereeEvent, WorldCommand, WorldSnapshot
from simulator.api import ApiServer, LockstepSettings, stepping_for
from simulator.telemetry import POSES_PERIOD_S, STATE_PERIOD_S, Telemetry
from simulator.traffic import TrafficLog

log = logging.getLogger(__name__)


class RefereeLike(Protocol):
    @property
    def finished(self) -> bool: ...

    @property
    def waiting_for_wall_clock(self) -> bool: ...

    @property
    def game_state(self) -> GameStateRecord: ...

    events: list[RefereeEvent]

    def step(self, snapshot: WorldSnapshot) -> list[WorldCommand]: ...


class WorldLike(Protocol):
    sim_time_ms: int
    step_ms: int
    data: Any  # mujoco.MjData: xpos and xquat are sent to live viewers

    def step(self) -> None: ...

    def snapshot(self) -> WorldSnapshot: ...

    def apply(self, command: WorldCommand) -> None: ...


class RecorderLike(Protocol):
    def record(self, world: Any, game_state: GameStateRecord) -> None: ...

    def event(self, event: EventRecord) -> None: ...


@dataclass(frozen=True, slots=True, kw_only=True)
class LoopSettings:
    stepping: str  # "async" | "lockstep" | "pipelined"
    maximum_real_time_factor: float
    lockstep: LockstepSettings
    end_of_game_real_s: float
    max_duration_real_s: float | None


class MatchLoop:
    """Runs a match until FINISHED (+ the end-of-game wait), the time limit or a stop request."""

    def __init__(
        self,
        *,
        world: WorldLike,
        referee: RefereeLike,
        server: ApiServer,
        recorder: RecorderLike | None,
        telemetry: Telemetry,
        settings: LoopSettings,
        traffic: TrafficLog | None = None,
    ) -> None:
        self.world = world
        self.referee = referee
        self.server = server
        self.recorder = recorder
        self.telemetry = telemetry
        self.settings = settings
        self.traffic = traffic
        self.stop_requested = False
        self.stop_reason = ""
        self.steps = 0
        self.held_s = 0.0
        self.real_time_s = 0.0
        self._events_seen = 0
        self._next_state_s = 0.0
        self._connection_changes = 0
        self._next_poses_s = 0.0
        self._rtf_window: tuple[float, int] = (0.0, 0)
        self._rtf = 0.0
        # (no prefetch of the next step's position stage: on a quiet 2-core machine it made
        # lockstep slower, README "The next step's position stage while lockstep waits")
        self.stepping = stepping_for(settings.stepping, server, settings.lockstep)

    def request_stop(self, reason: str) -> None:
        self.stop_requested = True
        self.stop_reason = reason
        self.server.stop_requested = True

    @property
    def lockstep(self) -> bool:
        """Lockstep or pipelined: steps wait for the clients and the wall-clock waits hold."""
        return self.stepping.holds

    def run(self) -> str:
        """Play; returns why the loop ended: finished, max_duration or the stop reason."""
        start = time.monotonic()
        self._rtf_window = (start, self.world.sim_time_ms)
        pace_origin = (start, self.world.sim_time_ms)
        max_rtf = self.settings.maximum_real_time_factor
        limit = self.settings.max_duration_real_s
        finished_at: float | None = None
        self._referee_step(self.world.snapshot())  # starting poses, ball on the centre spot
        while not self.stop_requested:
            now = time.monotonic()
            if limit is not None and now - start >= limit:
                self.stop_reason = "max_duration"
                log.warning("stopping: maximum duration of %.0f s (wall) reached", limit)
                break
            if self.referee.finished:
                if finished_at is None:
                    finished_at = now
                    log.info("game finished at %d ms of simulated time", self.world.sim_time_ms)
                if now - finished_at >= self.settings.end_of_game_real_s:
                    self.stop_reason = "finished"
                    break
            if self.stepping.holds and (
                self.referee.waiting_for_wall_clock or finished_at is not None
            ):
                self.stepping.hold(self.world.sim_time_ms, finished=finished_at is not None)
                self._hold(0.02)
                pace_origin = (time.monotonic(), self.world.sim_time_ms)
                continue
            self._one_step()
            if max_rtf > 0:
                origin_s, origin_ms = pace_origin
                due = origin_s + (self.world.sim_time_ms - origin_ms) / 1000.0 / max_rtf
                wait = due - time.monotonic()
                if wait < -1.0:  # far behind: do not try to catch up in a burst
                    pace_origin = (time.monotonic(), self.world.sim_time_ms)
                while wait > 0:  # a socket event ends a poll early: wait until due
                    self.server.poll(wait)
                    wait = due - time.monotonic()
        if not self.stop_requested:
            self.stepping.end(self.world.sim_time_ms)
        self.real_time_s = time.monotonic() - start
        self._publish_state(force=True)
        return self.stop_reason

    def _hold(self, seconds: float) -> None:
        began = time.monotonic()
        self.server.poll(seconds)
        self._referee_step(self.world.snapshot())  # lets the referee see its wait is over
        self._publish_state()
        self.held_s += time.monotonic() - began

    def _one_step(self) -> None:
        world, stepping = self.world, self.stepping
        stepping.before_step(world.sim_time_ms, world.sim_time_ms + world.step_ms)
        world.step()
        # the step's measurements go out first, then the referee looks at the step: its
        # commands (a penalty's removal, a placement) reach the robots' sensors from the next
        # step, as the league's referee acts between steps; in lockstep the robots answer
        # while the referee, the recorder and the telemetry run
        stepping.after_step(world.sim_time_ms)
        self._referee_step(world.snapshot())
        self.steps += 1
        if self.recorder is not None:
            self.recorder.record(world, self.referee.game_state.copy())
        self._publish_state()

    def _referee_step(self, snapshot: WorldSnapshot) -> None:
        for command in self.referee.step(snapshot):
            self.world.apply(command)
        events = self.referee.events
        while self._events_seen < len(events):
            if events[self._events_seen].type == "state":
                self._next_state_s = 0.0  # a new game state is published with this step
            payload = events[self._events_seen].to_record()
            self._events_seen += 1
            if self.recorder is not None:
                self.recorder.event(payload)
            self.telemetry.event(payload)

    def real_time_factor(self) -> float:
        now = time.monotonic()
        since, sim_ms = self._rtf_window
        if now - since >= 1.0:
            self._rtf = (self.world.sim_time_ms - sim_ms) / 1000.0 / (now - since)
            self._rtf_window = (now, self.world.sim_time_ms)
        return self._rtf

    def _publish_poses(self, now: float) -> None:
        if now < self._next_poses_s:
            return
        self._next_poses_s = now + POSES_PERIOD_S
        data = self.world.data
        poses = np.concatenate([data.xpos, data.xquat], axis=1).astype("<f4")
        self.telemetry.poses(struct.pack("<I", self.world.sim_time_ms) + poses.tobytes())

    def _publish_state(self, *, force: bool = False) -> None:
        now = time.monotonic()
        self._publish_poses(now)
        changes = self.server.connection_changes
        if not force and now < self._next_state_s and changes == self._connection_changes:
            return  # a client came or went: the state tells it at once (bring-up is seen)
        self._connection_changes = changes
        self._next_state_s = now + STATE_PERIOD_S
        game = self.referee.game_state
        rtf = self.real_time_factor()
        robots = None
        if self.traffic is not None:
            self.traffic.sample(now_s=now, sim_time_ms=self.world.sim_time_ms, real_time_factor=rtf)
            robots = self.traffic.latest["robots"] if self.traffic.latest else None
        self.telemetry.state(
            StateMessage(
                sim_time_ms=self.world.sim_time_ms,
                real_time_factor=round(rtf, 3),
                state=game.get("state"),
                secondary_state=game.get("secondary_state"),
                half=game.get("half"),
                secs_remaining=game.get("secs_remaining"),
                score=game.get("score"),
                connected=tuple(self.server.connected()),
                stepping=self.settings.stepping,
                robots=robots,
            ).to_dict()
        )
