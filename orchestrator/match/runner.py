"""Runs one match from a :class:`MatchPlan` to a complete output folder.

Phases (see :mod:`orchestrator.match.state`): images are resolved (PULLING); networks, the
simulator and the robots are started (STARTING, :func:`~orchestrator.match.startup.start`); the
runner waits for the game to leave INITIAL (WAITING) and watches the simulator, its telemetry and
the robots (PLAYING) until the simulator exits; robots get their grace period (STOPPING); logs
and results are collected and every object removed (COLLECTING,
:func:`~orchestrator.match.collection.collect`). ``report.json`` is written last, whatever
happened.

The runner owns one match's state: the lifecycle, the ledger of what was created
(:class:`~orchestrator.match.startup.Created`), the robots' records and how the game went so far.
The phases get what they need as arguments (the read-only
:class:`~orchestrator.match.deps.MatchDeps` first) and return what they produce; observers
follow :attr:`MatchRunner.events`.

Bandwidth limits are in place before a robot can send anything: each robot's network namespace
belongs to a holder container that is started and shaped first; the robot container is then
started inside that namespace.
"""

from __future__ import annotations

import logging
import threading
import time
from collections.abc import Callable, Mapping
from dataclasses import dataclass, replace
from pathlib import Path

from contracts import Color, Forfeit, MatchResults, RobotResult, StateMessage, files
from orchestrator.errors import EngineLost, OrchestratorError
from orchestrator.match.collection import (
    Played,
    collect,
    read_sim_result,
    reserve_space,
    simulator_stderr_tail,
)
from orchestrator.match.deps import MatchDeps, RunOptions, TelemetryFactory
from orchestrator.match.events import (
    AllConnected,
    EventStream,
    MatchEnded,
    RobotExited,
    StateChanged,
)
from orchestrator.match.host import Host
from orchestrator.match.monitor import StatsMonitor
from orchestrator.match.plan import MatchPlan
from orchestrator.match.results import Failure, FailureClass, RobotRecord
from orchestrator.match.startup import (
    Created,
    StartedMatch,
    StartupTimes,
    read_gated_counters,
    start,
)
from orchestrator.match.state import Lifecycle, MatchState
from orchestrator.runtime.port import ContainerRuntime

log = logging.getLogger(__name__)

# a container's exit code when SIGINT, SIGKILL or SIGTERM ended it
STOP_SIGNAL_CODES = (130, 137, 143)
# until every robot is connected (at most this long after STARTING) the simulator and its
# telemetry are polled every 0.1 s: the match goes on, and bring-up is seen, without a 0.5 s lag
BRINGUP_FAST_POLL_S = 30.0

ImageResolver = Callable[[MatchPlan], Mapping[str, tuple[str | None, str | None]]]
"""plan -> {robot key: (digest, error)}; a robot with an error has no usable image."""


@dataclass(frozen=True, slots=True, kw_only=True)
class MatchOutcome:
    match_id: str
    failure: Failure | None
    out_dir: Path
    results: MatchResults | None  # None: a match played elsewhere left no results.json
    bringup_s: float | None  # start of STARTING -> every robot connected (from telemetry)
    startup: StartupTimes | None = None  # STARTING's breakdown (None: it did not finish)

    @property
    def ok(self) -> bool:
        return self.failure is None


def local_images(runtime: ContainerRuntime) -> ImageResolver:
    """Images as they are on the engine: present -> its digest; missing -> an error."""

    def resolve(plan: MatchPlan) -> dict[str, tuple[str | None, str | None]]:
        found: dict[str, tuple[str | None, str | None]] = {}
        for robot in plan.robots:
            if robot.image is None:
                found[robot.key] = (None, "no image named for this player")
                continue
            digest = runtime.image_digest(robot.image)
            found[robot.key] = (digest, None if digest else f"image {robot.image} not found")
        return found

    return resolve


@dataclass(slots=True)
class _Game:
    """How the match has gone so far: the runner's own record, handed to collection as
    :class:`~orchestrator.match.collection.Played`. The robots' records are filled in as the
    match runs (images, then starts, then exits during the game)."""

    robots: dict[str, RobotRecord]
    failure: Failure | None = None  # the first failure (announced when recorded)
    forfeit: Forfeit | None = None
    bringup_s: float | None = None
    startup: StartupTimes | None = None  # STARTING's breakdown, once it is done

    def played(self) -> Played:
        return Played(robots=self.robots, failure=self.failure, forfeit=self.forfeit,
                      bringup_s=self.bringup_s)


class MatchRunner:
    """Runs the phases of one match in order; see the module docstring."""

    def __init__(
        self,
        plan: MatchPlan,
        *,
        runtime: ContainerRuntime,
        host: Host,
        options: RunOptions,
        images: ImageResolver | None = None,
        telemetry: TelemetryFactory | None = None,
        stop_event: threading.Event | None = None,
        clock: Callable[[], float] = time.monotonic,
    ) -> None:
        self.events = EventStream()  # the match's progress, for observers in other threads
        self.stop_event = stop_event or threading.Event()  # set: the match stops (interrupted)
        self._deps = MatchDeps(
            plan=plan, runtime=runtime, host=host, options=options, clock=clock,
            events=self.events, monitor=StatsMonitor(runtime), telemetry=telemetry,
        )
        self._images = images or local_images(runtime)

    # public -------------------------------------------------------------------------------
    def run(self) -> MatchOutcome:
        """Play the match; :attr:`events` tells observers how it goes, ending with
        :class:`~orchestrator.match.events.MatchEnded`."""
        plan = self._deps.plan
        lifecycle = Lifecycle(plan.match_id, clock=self._deps.clock)
        lifecycle.observers.append(self._entered)
        game = _Game(robots={
            r.key: RobotRecord(key=r.key, color=r.color, number=r.number,
                               entry=RobotResult(image=r.image))
            for r in plan.robots
        })
        try:
            return self._run(lifecycle, Created(), game)
        finally:
            self.events.publish(MatchEnded(failure=game.failure))

    # phases run by run() -----------------------------------------------------------------
    def _run(self, lifecycle: Lifecycle, created: Created, game: _Game) -> MatchOutcome:
        deps = self._deps
        out = deps.options.out_dir
        out.mkdir(parents=True, exist_ok=True)
        out.chmod(0o700)  # the teams' logs are theirs: owner-only (see collection)
        (out / files.REPORT).unlink(missing_ok=True)  # a stale one would say "complete"
        reserve_space(out)  # the results find room on a disk that fills during the match
        try:
            lifecycle.advance(MatchState.PULLING)
            self._resolve_images(game)
            if game.failure is None and game.forfeit is None:
                lifecycle.advance(MatchState.STARTING)
                started_at = deps.clock()
                started = start(deps, created, game.robots, started_at)
                try:
                    game.failure, game.startup = started.failure, started.times
                    if game.failure is None:
                        lifecycle.advance(MatchState.WAITING)
                        self._watch(lifecycle, started, game, started_at, created)
                finally:
                    if started.telemetry is not None:
                        started.telemetry.close()
        except OrchestratorError as exc:
            log.error("match %s: %s", deps.plan.match_id, exc)
            game.failure = deps.fail(game.failure, FailureClass.INFRASTRUCTURE, str(exc))
        except KeyboardInterrupt:
            game.failure = deps.fail(game.failure, FailureClass.INTERRUPTED, "interrupted")
        except Exception as exc:  # a bug: still stop and remove everything, then re-raise
            game.failure = deps.fail(game.failure, FailureClass.INFRASTRUCTURE,
                                     f"internal error: {exc!r}")
            collect(deps, lifecycle, created, game.played())
            raise
        results = collect(deps, lifecycle, created, game.played())
        game.failure = results.failure
        return MatchOutcome(
            match_id=deps.plan.match_id, failure=results.failure, out_dir=out, results=results,
            bringup_s=game.bringup_s, startup=game.startup,
        )

    def _entered(self, state: MatchState) -> None:
        """The lifecycle entered ``state``: observers and the console are told."""
        self.events.publish(StateChanged(state=state))
        self._progress(state, None)

    def _progress(self, state: MatchState, latest: StateMessage | None) -> None:
        if self._deps.options.progress is not None:
            self._deps.options.progress(state.value, latest)

    def _resolve_images(self, game: _Game) -> None:
        """Each robot's image digest or error into its record; a team without any usable
        image forfeits, both without: the match fails."""
        plan = self._deps.plan
        resolved = self._images(plan)
        usable: dict[str, int] = {"red": 0, "blue": 0}
        for key, (digest, error) in resolved.items():
            record = game.robots[key]
            record.entry = replace(record.entry, digest=digest, image_error=error)
            if error is None:
                usable[record.color] += 1
            else:
                log.warning("match %s: robot %s has no usable image: %s",
                            plan.match_id, key, error)
        forfeiting: list[Color] = [c for c in ("red", "blue") if usable[c] == 0]
        first_error = {
            color: next((f"{r.key}: {r.entry.image_error}" for r in game.robots.values()
                         if r.color == color and r.entry.image_error), "no players")
            for color in forfeiting
        }
        if len(forfeiting) == 2:
            game.failure = self._deps.fail(
                game.failure, FailureClass.IMAGE_PULL,
                "neither team has a usable image (" + "; ".join(first_error.values()) + ")")
        elif forfeiting:
            loser = forfeiting[0]
            winner: Color = "blue" if loser == "red" else "red"
            game.forfeit = Forfeit(
                team=loser,
                winner=winner,
                reason=f"no robot of {loser} has a usable image ({first_error[loser]})",
                score={winner: 0, loser: 0},
            )
            log.info("match %s: %s forfeits (no usable image)", plan.match_id, loser)

    def _watch(self, lifecycle: Lifecycle, started: StartedMatch, game: _Game,
               started_at: float, created: Created) -> None:
        """Poll the simulator, its telemetry and the robots until the simulator exits; what
        happens goes into ``game`` (the bring-up time, robots' exits, the failure)."""
        deps = self._deps
        plan, telemetry = deps.plan, started.telemetry
        last_robot_poll = 0.0
        while True:
            if self.stop_event.is_set():
                game.failure = deps.fail(game.failure, FailureClass.INTERRUPTED,
                                         "the orchestrator was asked to stop")
                return
            state = deps.runtime.inspect(started.simulator_id)
            if state.exited:
                self._on_simulator_exit(state.exit_code, started, game, created)
                return
            now = deps.clock()
            if now - last_robot_poll >= 2.0:
                self._poll_robots(started, game)
                for key in created.gated:  # their counters end with their containers
                    if not game.robots[key].entry.exited_during_game:
                        read_gated_counters(deps, created, key)
                last_robot_poll = now
            latest = telemetry.latest() if telemetry else None
            if lifecycle.state is MatchState.WAITING and (
                telemetry is None
                or (latest is not None and latest.state not in (None, "INITIAL"))
            ):
                lifecycle.advance(MatchState.PLAYING)
            if game.bringup_s is None and latest is not None:
                expected = set(started.robot_ids)
                if expected and expected <= set(latest.connected):
                    game.bringup_s = now - started_at
                    self.events.publish(AllConnected(bringup_s=game.bringup_s))
                    log.info("match %s: all %d robots connected after %.2f s",
                             plan.match_id, len(expected), game.bringup_s)
            if telemetry is not None:
                heard = telemetry.last_message_at() or started.simulator_started_at
                if now - heard > plan.telemetry_silence_s:
                    game.failure = deps.fail(game.failure, FailureClass.SIMULATOR,
                                             f"telemetry silent for {now - heard:.0f} s")
                    return
            self._progress(lifecycle.state, latest)
            poll_s = deps.options.poll_s
            bringing_up = game.bringup_s is None and now - started_at < BRINGUP_FAST_POLL_S
            self.stop_event.wait(min(poll_s, 0.1) if bringing_up else poll_s)

    def _poll_robots(self, started: StartedMatch, game: _Game) -> None:
        match_id = self._deps.plan.match_id
        for key, container_id in started.robot_ids.items():
            record = game.robots[key]
            if record.entry.exited_during_game:
                continue
            try:
                state = self._deps.runtime.inspect(container_id)
            except OrchestratorError as exc:
                log.warning("match %s: cannot inspect robot %s: %s", match_id, key, exc)
                continue
            if state.exited:
                record.entry = replace(record.entry, exited_during_game=True,
                                       exit_code=state.exit_code, oom_killed=state.oom_killed)
                self.events.publish(RobotExited(
                    key=key, color=record.color, image=record.entry.image,
                    exit_code=state.exit_code, oom_killed=state.oom_killed))
                log.info(
                    "match %s: robot %s exited during the game (code %s%s); the game goes on",
                    match_id, key, state.exit_code,
                    ", OOM-killed" if state.oom_killed else "",
                )

    def _on_simulator_exit(self, exit_code: int | None, started: StartedMatch, game: _Game,
                           created: Created) -> None:
        deps = self._deps
        match_id = deps.plan.match_id
        log.info("match %s: simulator exited with code %s", match_id, exit_code)
        sim_result = read_sim_result(started.match_dir, match_id=match_id)
        stopped_by = self._engine_stopped(created) if exit_code != 0 else None
        if stopped_by is not None:
            game.failure = deps.fail(
                game.failure, FailureClass.INFRASTRUCTURE,
                f"{stopped_by} (the simulator ended with code {exit_code})")
        elif exit_code != 0:
            reported = sim_result.error if sim_result is not None else None
            tail = str(reported) if reported else simulator_stderr_tail(
                deps.runtime, started.simulator_id, started.match_dir)
            game.failure = deps.fail(
                game.failure, FailureClass.SIMULATOR,
                f"simulator exited with code {exit_code}" + (f": {tail}" if tail else ""))
        elif sim_result is None:
            game.failure = deps.fail(game.failure, FailureClass.SIMULATOR,
                                     "simulator exited 0 without sim_result.json")
        elif not sim_result.finished:
            game.failure = deps.fail(game.failure, FailureClass.REFEREE,
                                     f"the game ended in state {sim_result.state}, not FINISHED")

    def _engine_stopped(self, created: Created) -> str | None:
        """Why the simulator's end was the engine's doing, None: it was the simulator's own.

        A network holder only sleeps and never exits by itself: when one has ended with the
        simulator, something outside the match stopped its containers (the engine stopping or
        restarting stops them all); an engine that no longer answers says so too. Without
        holders (robots behind the start gate) the simulator's own exit code tells it: the
        simulator ends by a stop signal only when one was sent to it."""
        runtime = self._deps.runtime
        for key, holder_id in created.holder_ids.items():
            try:
                state = runtime.inspect(holder_id)
            except EngineLost as exc:
                return f"{exc}; it stopped the match's containers"
            except OrchestratorError:
                continue
            if state.exited:
                return (f"the Docker engine at {runtime.endpoint()} stopped the match's "
                        f"containers (it was stopped or restarted, or they were stopped from "
                        f"outside the runner): the network holder of {key} ended with code "
                        f"{state.exit_code} as well")
        if created.holder_ids or created.simulator_id is None:
            return None
        # robots behind the start gate have no holders: a simulator ended by a stop signal
        # that the runner did not send (nor the kernel's OOM killer) was stopped from outside
        try:
            state = runtime.inspect(created.simulator_id)
        except EngineLost as exc:
            return f"{exc}; it stopped the match's containers"
        except OrchestratorError:
            return None
        if state.exit_code in STOP_SIGNAL_CODES and not state.oom_killed:
            return (f"the Docker engine at {runtime.endpoint()} stopped the match's containers "
                    f"(it was stopped or restarted, or they were stopped from outside the "
                    f"runner): the simulator ended by a signal (code {state.exit_code})")
        return None


__all__ = ["ImageResolver", "MatchOutcome", "MatchRunner", "RunOptions", "TelemetryFactory",
           "local_images"]
