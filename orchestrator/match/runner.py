"""Runs one match from a :class:`MatchPlan` to a complete output folder.

Phases (see :mod:`orchestrator.match.state`): images are resolved (PULLING); networks, the
simulator and the robots are started (STARTING); the runner waits for the game to leave INITIAL
(WAITING) and watches the simulator, its telemetry and the robots (PLAYING) until the simulator
exits; robots get their grace period (STOPPING); logs and results are collected and every object
removed (COLLECTING). ``report.json`` is written last, whatever happened.

Bandwidth limits are in place before a robot can send anything: each robot's network namespace
belongs to a holder container that is started and shaped first; the robot container is then
started inside that namespace.
"""

from __future__ import annotations

import logging
import threading
import time
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from pathlib import Path

from contracts import Color, Forfeit, MatchResults, files
from orchestrator.errors import OrchestratorError
from orchestrator.match.collection import CollectionPhase, read_sim_result, simulator_stderr_tail
from orchestrator.match.context import MatchContext, RunOptions, TelemetryFactory
from orchestrator.match.events import AllConnected, MatchEnded, RobotExited
from orchestrator.match.host import Host
from orchestrator.match.plan import MatchPlan
from orchestrator.match.results import Failure, FailureClass
from orchestrator.match.runtime import ContainerRuntime
from orchestrator.match.startup import StartupPhase
from orchestrator.match.state import MatchState

log = logging.getLogger(__name__)

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


class MatchRunner(MatchContext):
    """Runs the phases of one match in order on its :class:`MatchContext`."""

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
        super().__init__(
            plan, runtime=runtime, host=host, options=options, telemetry=telemetry,
            stop_event=stop_event, clock=clock,
        )  # fmt: skip
        self.images = images or local_images(runtime)

    # public -------------------------------------------------------------------------------
    def run(self) -> MatchOutcome:
        """Play the match; :attr:`events` tells observers how it goes, ending with
        :class:`~orchestrator.match.events.MatchEnded`."""
        try:
            return self._run()
        finally:
            self.events.publish(MatchEnded(failure=self.failure))

    def _run(self) -> MatchOutcome:
        out = self.options.out_dir
        out.mkdir(parents=True, exist_ok=True)
        out.chmod(0o700)  # the teams' logs are theirs: owner-only (see collection)
        (out / files.REPORT).unlink(missing_ok=True)  # a stale one would say "complete"
        try:
            self.advance(MatchState.PULLING)
            self._resolve_images()
            if self.failure is None and self.forfeit is None:
                self.advance(MatchState.STARTING)
                started_at = self.clock()
                StartupPhase(self).run(started_at)
                if self.failure is None:
                    self.advance(MatchState.WAITING)
                    self._watch(started_at)
        except OrchestratorError as exc:
            log.error("match %s: %s", self.plan.match_id, exc)
            self.fail(FailureClass.INFRASTRUCTURE, str(exc))
        except KeyboardInterrupt:
            self.fail(FailureClass.INTERRUPTED, "interrupted")
        except Exception as exc:  # a bug: still stop and remove everything, then re-raise
            self.fail(FailureClass.INFRASTRUCTURE, f"internal error: {exc!r}")
            CollectionPhase(self).run()
            raise
        results = CollectionPhase(self).run()
        return MatchOutcome(
            match_id=self.plan.match_id, failure=self.failure, out_dir=out, results=results,
            bringup_s=self.bringup_s,
        )

    # phases run by run() -----------------------------------------------------------------
    def _resolve_images(self) -> None:
        resolved = self.images(self.plan)
        usable: dict[str, int] = {"red": 0, "blue": 0}
        for key, (digest, error) in resolved.items():
            record = self.records[key]
            record.digest = digest
            record.image_error = error
            if error is None:
                usable[record.color] += 1
            else:
                log.warning("match %s: robot %s has no usable image: %s",
                            self.plan.match_id, key, error)
        forfeiting: list[Color] = [c for c in ("red", "blue") if usable[c] == 0]
        first_error = {
            color: next((f"{r.key}: {r.image_error}" for r in self.records.values()
                         if r.color == color and r.image_error), "no players")
            for color in forfeiting
        }
        if len(forfeiting) == 2:
            self.fail(FailureClass.IMAGE_PULL, "neither team has a usable image ("
                       + "; ".join(first_error.values()) + ")")
        elif forfeiting:
            loser = forfeiting[0]
            winner: Color = "blue" if loser == "red" else "red"
            self.forfeit = Forfeit(
                team=loser,
                winner=winner,
                reason=f"no robot of {loser} has a usable image ({first_error[loser]})",
                score={winner: 0, loser: 0},
            )
            log.info("match %s: %s forfeits (no usable image)", self.plan.match_id, loser)

    def _watch(self, started_at: float) -> None:
        """Poll the simulator, its telemetry and the robots until the simulator exits."""
        sim_id = self.started.simulator_id
        assert sim_id is not None
        last_robot_poll = 0.0
        while True:
            if self.stop_event.is_set():
                self.fail(FailureClass.INTERRUPTED, "the orchestrator was asked to stop")
                return
            state = self.runtime.inspect(sim_id)
            if state.exited:
                self._on_simulator_exit(state.exit_code)
                return
            now = self.clock()
            if now - last_robot_poll >= 2.0:
                self._poll_robots()
                last_robot_poll = now
            latest = self.telemetry.latest() if self.telemetry else None
            if self.lifecycle.state is MatchState.WAITING and (
                self.telemetry is None
                or (latest is not None and latest.state not in (None, "INITIAL"))
            ):
                self.advance(MatchState.PLAYING)
            if self.bringup_s is None and latest is not None:
                expected = {k for k in self.started.robot_ids}
                if expected and expected <= set(latest.connected):
                    self.bringup_s = now - started_at
                    self.events.publish(AllConnected(bringup_s=self.bringup_s))
                    log.info("match %s: all %d robots connected after %.2f s",
                             self.plan.match_id, len(expected), self.bringup_s)
            if self.telemetry is not None:
                heard = self.telemetry.last_message_at() or self.started.simulator_started_at
                if now - heard > self.plan.telemetry_silence_s:
                    self.fail(FailureClass.SIMULATOR,
                               f"telemetry silent for {now - heard:.0f} s")
                    return
            self.progress(latest)
            bringing_up = self.bringup_s is None and now - started_at < BRINGUP_FAST_POLL_S
            self.stop_event.wait(min(self.options.poll_s, 0.1) if bringing_up
                                 else self.options.poll_s)

    def _poll_robots(self) -> None:
        for key, container_id in self.started.robot_ids.items():
            record = self.records[key]
            if record.exited_during_game:
                continue
            try:
                state = self.runtime.inspect(container_id)
            except OrchestratorError as exc:
                log.warning("match %s: cannot inspect robot %s: %s", self.plan.match_id, key, exc)
                continue
            if state.exited:
                record.exited_during_game = True
                record.exit_code = state.exit_code
                record.oom_killed = state.oom_killed
                self.events.publish(RobotExited(
                    key=key, color=record.color, image=record.image,
                    exit_code=state.exit_code, oom_killed=state.oom_killed))
                log.info(
                    "match %s: robot %s exited during the game (code %s%s); the game goes on",
                    self.plan.match_id, key, state.exit_code,
                    ", OOM-killed" if state.oom_killed else "",
                )

    def _on_simulator_exit(self, exit_code: int | None) -> None:
        log.info("match %s: simulator exited with code %s", self.plan.match_id, exit_code)
        if exit_code != 0:
            written = read_sim_result(self)
            reported = written.error if written is not None else None
            tail = str(reported) if reported else simulator_stderr_tail(self)
            self.fail(FailureClass.SIMULATOR,
                       f"simulator exited with code {exit_code}" + (f": {tail}" if tail else ""))
            return
        sim_result = read_sim_result(self)
        if sim_result is None:
            self.fail(FailureClass.SIMULATOR, "simulator exited 0 without sim_result.json")
        elif not sim_result.finished:
            self.fail(FailureClass.REFEREE,
                       f"the game ended in state {sim_result.state}, not FINISHED")


__all__ = ["ImageResolver", "MatchOutcome", "MatchRunner", "RunOptions", "TelemetryFactory",
           "local_images"]
