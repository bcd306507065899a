"""The automatic referee: drives the GameController from world snapshots and applies the rules.

:class:`Referee` is the facade the simulator runtime uses: ``step(snapshot)`` every basic step
(8 ms of simulated time) returns the world commands to apply before the next step. The game
clock runs on simulated time; the league's wall-clock waits (before the first READY, between
periods) use the injected clock and are visible as ``waiting_for_wall_clock``.
"""

from __future__ import annotations

import logging
from collections.abc import Callable
from pathlib import Path

from contracts import GameStateRecord, GameType, RobotId, TeamColor
from referee import placement, positions, reporting
from referee.clock import Clock, SystemClock, WallClockWait
from referee.config import RefereeConfig
from referee.gamecontroller import (
    GameController,
    GameState,
    SecondaryState,
    Tick,
)
from referee.gamecontroller.states import Card
from referee.gc_link import GameControllerLink
from referee.judgement import PenaltyBook, apply_decisions, penalised_robots
from referee.logs import RefereeLog
from referee.mirror import TeamMirror
from referee.net import GameControllerNetwork
from referee.play_stats import PlayTracker
from referee.rulebook import RuleBook
from referee.rules import end_of_game, goal, kickoff, set_play
from referee.rules.base import AbortSetPlay, Decision, GameView, GiveCard, RetakeSetPlay
from referee.shootout_play import ShootoutPlay
from referee.snapshot import (
    PlaceBall,
    RefereeEvent,
    Vec2,
    WorldCommand,
    WorldSnapshot,
)
from referee.spoofing import SpoofingLog

logger = logging.getLogger(__name__)

Action = Callable[[WorldSnapshot], list[WorldCommand]]
_PREDECESSOR = {
    GameState.INITIAL: GameState.FINISHED,
    GameState.READY: GameState.PLAYING,
    GameState.SET: GameState.INITIAL,
    GameState.PLAYING: GameState.SET,
    GameState.FINISHED: GameState.READY,
}


def _game_controller(config: RefereeConfig) -> GameController:
    """A GameController for the teams, kick-off, timing and goalkeepers of ``config``."""
    keepers = {
        color: next((p.number for p in config.team(color).players if p.goalkeeper), None)
        for color in (TeamColor.RED, TeamColor.BLUE)
    }
    return GameController(
        game_type=config.game_type,
        players={
            color: tuple(p.number for p in config.team(color).players)
            for color in (TeamColor.RED, TeamColor.BLUE)
        },
        kickoff=config.kickoff,
        timing=config.timing,
        goalkeepers={c: n for c, n in keepers.items() if n is not None},
    )


def _game_view(
    gc: GameController, *, left_team: TeamColor, ball_in_play: bool, config: RefereeConfig
) -> GameView:
    """What the rules see of the game now."""
    keepers = frozenset(
        RobotId(color, n)
        for color in (TeamColor.RED, TeamColor.BLUE)
        if (n := gc.goalkeeper(color)) is not None
    )
    return GameView(
        state=gc.state,
        phase=gc.phase,
        set_play=gc.set_play,
        half=gc.half,
        kickoff_team=gc.kickoff_team,
        left_team=left_team,
        ball_in_play=ball_in_play,
        penalised=frozenset(gc.penalised()),
        goalkeepers=keepers,
        field=config.field,
        timing=config.timing,
    )


class Referee:
    def __init__(
        self, *, config: RefereeConfig, clock: Clock | None = None, log_dir: Path | None = None
    ) -> None:
        self.config = config
        self.field = config.field
        self._clock: Clock = clock or SystemClock()
        self.log = RefereeLog(clock=self._clock, log_dir=log_dir)
        self.gc = _game_controller(config)
        self.left_team = config.side_left
        self.events: list[RefereeEvent] = []
        self.book = PenaltyBook()
        self._touches = reporting.TouchReporter()
        self._started = False
        self._last_ms: int | None = None
        self._waiting: WallClockWait[Action] = WallClockWait(self._clock)
        self._finished = False
        self._winner: TeamColor | None = None
        self._coin_toss = False
        self.set_since_ms: int | None = None
        self._shootout: ShootoutPlay | None = None
        self.ball_in_play = False
        self.set_play_spot: Vec2 | None = None  # where the set play in preparation puts the ball
        self._placed_ms: int | None = None  # when a set play's ball was last placed
        self._placed_at_start_ms: int | None = None  # when robots were last put at start poses
        self.play = PlayTracker()
        self.reset_memories()
        self.link = GameControllerLink(
            config=config, gc=self.gc, clock=self._clock, log=self.log, log_dir=log_dir,
            left_team=lambda: self.left_team,
        )
        self._status = reporting.StatusReporter(
            clock=self._clock, period_s=config.timing.status_period_real_s
        )

    # --- public surface ------------------------------------------------------------------

    @property
    def finished(self) -> bool:
        return self._finished

    @property
    def waiting_for_wall_clock(self) -> bool:
        return self._waiting.pending

    @property
    def game_state(self) -> GameStateRecord:
        """The telemetry state dict: state, secondary_state, half, secs_remaining, score,
        penalties (and set_play, phase, kickoff, left_team, waiting_for_wall_clock)."""
        return reporting.game_state(
            self.gc, left_team=self.left_team, waiting=self.waiting_for_wall_clock
        )

    def result(self) -> dict[str, object]:
        """score, winner (red, blue, draw; None before the end), events_summary {type: count},
        spoofing {total, attempts}, play (:class:`contracts.sim_result.PlayRecord`)."""
        self._report_spoofing()
        out = reporting.result(
            self.gc, self.events, finished=self._finished, winner=self._winner,
            shootout=self._shootout is not None, coin_toss=self._coin_toss,
            play=self.play.stats(self.events),
        )
        out["spoofing"] = self.spoofing.to_json()
        return out

    def start_network(self) -> None:
        """Start the GameController sender / receiver and the team mirror (UDP)."""
        self.link.start(self._last_ms or 0)

    @property
    def network(self) -> GameControllerNetwork | None:
        return self.link.network

    @property
    def mirror(self) -> TeamMirror | None:
        return self.link.mirror

    @property
    def spoofing(self) -> SpoofingLog:
        return self.link.spoofing

    def close(self) -> None:
        self.link.close(self._last_ms or 0)
        self.log.close()

    def __enter__(self) -> Referee:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def step(self, snapshot: WorldSnapshot) -> list[WorldCommand]:
        commands: list[WorldCommand] = []
        # robots penalised before this step: this snapshot shows where they were put
        penalised = frozenset(self.gc.penalised())
        now = snapshot.sim_time_ms
        if not self._started:
            commands += self._start(snapshot)
        dt_ms = 0 if self._last_ms is None else max(0, now - self._last_ms)
        self._last_ms = now
        for line in self._status.lines(self.gc, snapshot.sim_time_ms):
            self.log.info(snapshot.sim_time_ms, line)
            if line.startswith("STATUS: state"):
                self.link.log_counts(snapshot.sim_time_ms)
        if (touch := self._touches.line(snapshot)) is not None:
            self.log.info(now, touch)
        self._report_spoofing()
        self.play.observe(snapshot, self.view())
        self.link.take_goalkeeper_claims(now)
        if self._finished:
            return commands
        if self._waiting.pending:
            # INITIAL: the GameController's time runs on, this step's before the wait's end
            self.gc.advance_ms(dt_ms)
            dt_ms = 0
            if not self._waiting.over():
                self._publish()
                return commands
            action = self._waiting.take()
            if action is not None:
                commands += action(snapshot)
        tick = self.gc.advance_ms(dt_ms)
        commands += self._on_tick(tick, snapshot)
        if self.gc.state is not GameState.INITIAL and not self._finished:
            commands += penalised_robots(self, snapshot, penalised)
        if not self._finished and not self._waiting.pending:
            if self.gc.phase is SecondaryState.PENALTYSHOOT:
                commands += self._shootout_step(snapshot)
            else:
                commands += self._play_step(snapshot)
        self._publish()
        return commands

    # --- flow ----------------------------------------------------------------------------

    def reset_memories(self) -> None:
        self.rules = RuleBook()

    def view(self) -> GameView:
        return _game_view(
            self.gc, left_team=self.left_team, ball_in_play=self.ball_in_play, config=self.config
        )

    def ball_at(self, x_m: float, y_m: float) -> PlaceBall:
        return PlaceBall(position=(x_m, y_m, self.field.ball_radius_m))

    def ball_away(self) -> PlaceBall:
        """The ball held off the field until SET places it for the kick-off: in INITIAL and READY
        before each period and after a goal, as the league's referee holds it there
        (hlvs_webots referee.py:1762-1768, ``kickoff`` calling ``move_ball_away``)."""
        return self.ball_at(*positions.BALL_AWAY_XY)

    def emit(self, event: RefereeEvent) -> None:
        self.events.append(event)
        self.log.event(event)

    def _wait(self, seconds: float, action: Action, why: str, sim_ms: int) -> None:
        self._waiting.start(seconds, action)
        self.log.info(sim_ms, f"Waiting {seconds:g} s of real time {why}.")

    def _start(self, snapshot: WorldSnapshot) -> list[WorldCommand]:
        self._started = True
        self.reset_memories()
        cfg = self.config
        self.log.info(
            snapshot.sim_time_ms,
            f"Game type {cfg.game_type.value}, {cfg.field_class.value} field: "
            f"red {cfg.red.name} ({cfg.red.team_id}) vs blue {cfg.blue.name} ({cfg.blue.team_id}),"
            f" {self.left_team.value} on the left, kick-off {cfg.kickoff.value}.",
        )
        commands = positions.starting_positions(self, snapshot.sim_time_ms)
        self._placed_at_start_ms = snapshot.sim_time_ms
        if cfg.game_type is GameType.PENALTY:
            self._wait(cfg.timing.wait_before_first_ready_real_s, self._begin_shootout,
                       "before the penalty shoot-out", snapshot.sim_time_ms)
        else:
            self._wait(cfg.timing.wait_before_first_ready_real_s, self._to_ready,
                       "before the first READY", snapshot.sim_time_ms)
        return commands

    def _to_ready(self, snapshot: WorldSnapshot) -> list[WorldCommand]:
        self.gc.transition(GameState.READY)
        self.state_event(snapshot, "READY")
        if not self.config.start_positions_checked:
            return []
        if snapshot.sim_time_ms == self._placed_at_start_ms:
            # no wait before READY: the robots are put at their start positions this very step,
            # and this snapshot shows them where they were before
            return []
        return self.apply(kickoff.judge_start(snapshot, self.view()), snapshot)

    def state_event(self, snapshot: WorldSnapshot, what: str, **details: object) -> None:
        gc = self.gc
        kick = gc.kickoff_team.value if gc.kickoff_team is not None else "dropped ball"
        self.log.info(snapshot.sim_time_ms, f"State {what} (half {gc.half}, kick-off {kick}).")
        self.emit(
            RefereeEvent(
                sim_time_ms=snapshot.sim_time_ms, type="state", team=gc.kickoff_team,
                reason=what, details={"half": gc.half, "phase": gc.phase.name, **details},
            )
        )

    def _released(self, robots: tuple[RobotId, ...], now: int) -> list[WorldCommand]:
        """Robots whose penalty is over (served, or lifted as PLAYING begins): their motors
        back, an event each."""
        commands: list[WorldCommand] = []
        for robot in robots:
            commands += self.book.penalty_over(robot)
            self.log.info(now, f"Penalty of {robot} is over.")
            self.emit(RefereeEvent(sim_time_ms=now, type="unpenalised", team=robot.team,
                                   player=robot.number))
        return commands

    def _on_tick(self, tick: Tick, snapshot: WorldSnapshot) -> list[WorldCommand]:
        now = snapshot.sim_time_ms
        commands = self._released(tick.unpenalised, now)
        if tick.auto_set:
            self.set_since_ms = now
            self.state_event(snapshot, "SET")
            commands += positions.kick_off_ball(self, snapshot)
            commands += self.apply(kickoff.judge_set(snapshot, self.view()), snapshot)
        if tick.set_play_phase is not None and self.gc.set_play is not None:
            play = self.gc.set_play
            self.log.info(now, f"{play.kind.name} for {play.team.value}: phase {play.sub_phase}.")
            if play.sub_phase == 1:
                spot = self.set_play_spot
                if spot is None:
                    spot = (snapshot.ball.position[0], snapshot.ball.position[1])
                commands += placement.place_set_play_ball(self, snapshot, play, spot)
                self._placed_ms = now
        if tick.set_play_executed is not None:
            play = tick.set_play_executed
            self.log.info(now, f"{play.kind.name} for {play.team.value}: execute.")
            commands += self.apply(set_play.judge_execute(snapshot, self.view(), play), snapshot)
            restriction = {
                SecondaryState.THROW_IN: goal.Restriction.THROW_IN,
                SecondaryState.INDIRECT_FREEKICK: goal.Restriction.INDIRECT_FREE_KICK,
            }.get(play.kind)
            self.rules.restart(snapshot, restriction, play.team)
        if tick.period_over and self.gc.phase is not SecondaryState.PENALTYSHOOT:
            commands += self._end_period(snapshot)
        return commands

    def _play_step(self, snapshot: WorldSnapshot) -> list[WorldCommand]:
        gc = self.gc
        now = snapshot.sim_time_ms
        commands: list[WorldCommand] = []
        if gc.state is GameState.SET and self.set_since_ms is not None:
            if now - self.set_since_ms >= self.config.timing.set_to_play_s * 1000.0:
                commands += self._released(gc.play(), now)
                self.set_since_ms = None
                self.ball_in_play = False
                restriction = goal.Restriction.KICKOFF if gc.kickoff_team is not None else None
                self.rules.restart(snapshot, restriction)
                self.state_event(snapshot, "PLAYING")
        if gc.state not in (GameState.READY, GameState.SET, GameState.PLAYING):
            return commands
        view = self.view()
        decisions = self.rules.judge(snapshot, view)
        if self._placed_ms == now:
            # the ball was placed this step: a touch seen in this snapshot was of the ball where
            # it lay in sub-phase 0, where touching it is allowed
            decisions = [d for d in decisions if not isinstance(d, RetakeSetPlay | AbortSetPlay)]
        if gc.state is GameState.SET:
            # kick-off positions hold through SET: the league's referee checks them every step
            # of SET, not only when it begins (hlvs_webots referee.py:2358-2365)
            decisions += kickoff.judge_set(snapshot, view)
        return commands + self.apply(decisions, snapshot)

    def give_card(
        self, robot: RobotId, card: Card, reason: str, snapshot: WorldSnapshot
    ) -> list[WorldCommand]:
        """A card given by hand, as the league's human referee does at the GameController (the
        automatic rules give none). Escalates like every card; a red card removes the robot."""
        return self.apply([GiveCard(robot, card, reason)], snapshot)

    def force_state(self, state: GameState, snapshot: WorldSnapshot) -> list[WorldCommand]:
        """Put the game into ``state`` now, as a trainer may (learning environments): cancels a
        pending wall-clock wait and skips the transitions a match would take. READY goes on to
        SET when its time is up, SET to PLAYING after ``set_to_play_s``; PLAYING starts with the
        ball in play as after a dropped ball's SET. Returns the world commands to apply: the ball
        held off the field before a kick-off is put on the centre spot for SET or PLAYING, as
        SET would have put it."""
        commands: list[WorldCommand] = []
        if state in (GameState.SET, GameState.PLAYING):
            commands, snapshot = positions.ball_held_placed(self, snapshot)
        gc = self.gc
        self._started = True
        self._waiting.cancel()
        self.set_since_ms = snapshot.sim_time_ms if state is GameState.SET else None
        self.ball_in_play = False
        gc.state = _PREDECESSOR[state]  # a state from which the transition is allowed
        gc.transition(state)
        if state is GameState.PLAYING:
            self.rules.restart(snapshot, None)
        self.log.info(snapshot.sim_time_ms, f"State {state.name} set by the trainer.")
        return commands

    def apply(self, decisions: list[Decision], snapshot: WorldSnapshot) -> list[WorldCommand]:
        return apply_decisions(self, decisions, snapshot) if decisions else []

    def _end_period(self, snapshot: WorldSnapshot) -> list[WorldCommand]:
        gc = self.gc
        if gc.state is not GameState.FINISHED:
            gc.transition(GameState.FINISHED)
        score = {c: gc.score(c) for c in (TeamColor.RED, TeamColor.BLUE)}
        following = end_of_game.after_period(
            game_type=self.config.game_type, phase=gc.phase, half=gc.half, score=score
        )
        self.ball_in_play = False
        self.set_since_ms = None
        self.state_event(snapshot, "FINISHED", next=following.value)
        commands = self.book.revive_all()
        if following is end_of_game.Next.FINISHED:
            self.finish(snapshot, end_of_game.winner(score))
        else:
            self._publish()  # robots see FINISHED before the next period's INITIAL
            commands += self._next_period(snapshot, following)
        return commands

    def _next_period(
        self, snapshot: WorldSnapshot, following: end_of_game.Next
    ) -> list[WorldCommand]:
        """The break between periods, as the league's referee spends it: the GameController
        goes to INITIAL of the next period at once (``firstHalf`` 0 before the second half),
        sides change and robots are placed, then READY (or the shoot-out) after the break."""
        phase = self.gc.next_period()
        self.reset_memories()
        self.state_event(snapshot, "INITIAL")
        commands: list[WorldCommand] = []
        if phase is SecondaryState.PENALTYSHOOT:
            after: Action = self._begin_shootout
        else:
            self.left_team = self.left_team.opponent
            self.log.info(
                snapshot.sim_time_ms, f"Sides changed: {self.left_team.value} on the left."
            )
            commands = positions.starting_positions(self, snapshot.sim_time_ms)
            self._placed_at_start_ms = snapshot.sim_time_ms
            after = self._to_ready
        self._wait(self.config.timing.half_time_break_real_s, after,
                   f"before the {following.value}", snapshot.sim_time_ms)
        return commands

    def finish(
        self, snapshot: WorldSnapshot, winner: TeamColor | None, *, coin_toss: bool = False
    ) -> None:
        """The game is over: ``winner`` (None: a draw; ``coin_toss``: the shoot-out was decided
        by a coin toss)."""
        self._coin_toss = coin_toss
        self._finished = True
        self._winner = winner
        lines, event = reporting.game_over(
            self.gc, winner, coin_toss=coin_toss, sim_time_ms=snapshot.sim_time_ms
        )
        for line in lines:
            self.log.info(snapshot.sim_time_ms, line)
        self.emit(event)

    # --- penalty shoot-out ---------------------------------------------------------------

    def _begin_shootout(self, snapshot: WorldSnapshot) -> list[WorldCommand]:
        self._shootout = ShootoutPlay(self)
        return self._shootout.begin(snapshot)

    def _shootout_step(self, snapshot: WorldSnapshot) -> list[WorldCommand]:
        return [] if self._shootout is None else self._shootout.step(snapshot)

    # --- outputs -------------------------------------------------------------------------

    def _report_spoofing(self) -> None:
        self.link.report_spoofing(self._last_ms or 0, self.emit)

    def _publish(self, *, force: bool = False) -> None:
        self.link.publish(self._last_ms or 0, force=force)

    def packet(self) -> bytes:
        """The current ``RGme`` datagram (``packetNumber`` 0: the sender numbers its packets)."""
        return self.link.packet()
