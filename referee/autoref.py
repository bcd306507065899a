"""The automatic referee: drives the GameController from world snapshots and applies the rules.

:class:`Referee` is the facade the simulator runtime uses: ``step(snapshot)`` every basic step
(8 ms of simulated time) returns the world commands to apply before the next step. The game
clock runs on simulated time; the league's wall-clock waits (before the first READY, between
periods) use the injected clock and are visible as ``waiting_for_wall_clock``.
"""

from __future__ import annotations

import logging
import math
from collections.abc import Callable
from dataclasses import replace
from pathlib import Path

from contracts import GameStateRecord, GameType, Pose, RobotId, TeamColor
from referee import placement, reporting
from referee.clock import Clock, SystemClock
from referee.config import RefereeConfig
from referee.gamecontroller import (
    LEAGUE_PLAYERS_PER_TEAM,
    GameController,
    GameState,
    SecondaryState,
    Tick,
)
from referee.gamecontroller.states import Card
from referee.judgement import apply_decisions, penalised_robots
from referee.logs import RefereeLog
from referee.mirror import TeamMirror
from referee.net import GameControllerNetwork
from referee.play_stats import PlayTracker
from referee.publisher import Publisher
from referee.rulebook import RuleBook
from referee.rules import end_of_game, goal, kickoff, set_play
from referee.rules.base import AbortSetPlay, Decision, GameView, GiveCard, RetakeSetPlay
from referee.shootout import KickOutcome, Shootout
from referee.snapshot import (
    BallState,
    PlaceBall,
    RefereeEvent,
    SetLimp,
    TeleportRobot,
    Vec2,
    WorldCommand,
    WorldSnapshot,
)
from referee.spoofing import Senders, SpoofingLog, robot_key

logger = logging.getLogger(__name__)

Action = Callable[[WorldSnapshot], list[WorldCommand]]
BALL_ON_SPOT_M = 0.01  # a ball farther from the centre spot at SET was moved in READY (logged)
# Where the ball is held before a kick-off, off the field, as the league's referee holds it
# "in its hand" (hlvs_webots referee.py:1756-1760, ``move_ball_away``)
BALL_AWAY_XY = (100.0, 100.0)
_PREDECESSOR = {
    GameState.INITIAL: GameState.FINISHED,
    GameState.READY: GameState.PLAYING,
    GameState.SET: GameState.INITIAL,
    GameState.PLAYING: GameState.SET,
    GameState.FINISHED: GameState.READY,
}


class Referee:
    def __init__(
        self, *, config: RefereeConfig, clock: Clock | None = None, log_dir: Path | None = None
    ) -> None:
        self.config = config
        self.field = config.field
        self._clock: Clock = clock or SystemClock()
        self.log = RefereeLog(clock=self._clock, log_dir=log_dir)
        self._log_dir = log_dir
        keepers = {
            color: next((p.number for p in config.team(color).players if p.goalkeeper), None)
            for color in (TeamColor.RED, TeamColor.BLUE)
        }
        self.gc = GameController(
            game_type=config.game_type,
            players={
                color: tuple(p.number for p in config.team(color).players)
                for color in (TeamColor.RED, TeamColor.BLUE)
            },
            kickoff=config.kickoff,
            timing=config.timing,
            goalkeepers={c: n for c, n in keepers.items() if n is not None},
        )
        self.left_team = config.side_left
        self.events: list[RefereeEvent] = []
        self.limp: set[RobotId] = set()
        self.red_carded: set[RobotId] = set()
        self.ignored_robots: set[RobotId] = set()
        self._last_toucher: RobotId | None = None
        self._last_touch_ms: int | None = None
        self._started = False
        self._last_ms: int | None = None
        self._wait_until_s: float | None = None
        self._after_wait: Action | None = None
        self._finished = False
        self._winner: TeamColor | None = None
        self._coin_toss = False
        self._set_since_ms: int | None = None
        self._shootout: Shootout | None = None
        self.ball_in_play = False
        self.set_play_spot: Vec2 | None = None  # where the set play in preparation puts the ball
        self._placed_ms: int | None = None  # when a set play's ball was last placed
        self.carried: dict[RobotId, Vec2] = {}  # where the referee last put a penalised robot
        self.settling: dict[RobotId, tuple[int, Pose]] = {}  # to be put there again, still
        self._placed_at_start_ms: int | None = None  # when robots were last put at start poses
        self.play = PlayTracker()
        self.reset_memories()
        self._network: GameControllerNetwork | None = None
        self._mirror: TeamMirror | None = None
        self.spoofing = SpoofingLog()
        self.senders = Senders({
            RobotId(color, n): address
            for color in (TeamColor.RED, TeamColor.BLUE)
            for n, address in enumerate(config.team(color).robot_addresses, start=1)
        })
        self._publisher = Publisher(
            gc=self.gc,
            team_numbers={c: config.team(c).team_id for c in (TeamColor.RED, TeamColor.BLUE)},
            players_per_team=LEAGUE_PLAYERS_PER_TEAM[config.field_class],
            left_team=lambda: self.left_team,
            log=self.log,
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
        return self._wait_until_s is not None

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
        net = self.config.network
        addresses = {
            color: tuple(self.config.team(color).robot_addresses)
            for color in (TeamColor.RED, TeamColor.BLUE)
        }
        self._network = GameControllerNetwork(
            bind_host=net.bind_host,
            data_port=net.gc_data_port,
            return_port=net.gc_return_port,
            targets=addresses[TeamColor.RED] + addresses[TeamColor.BLUE],
            team_numbers={self.config.team(c).team_id: c for c in addresses},
            send_rate_hz=net.send_rate_hz,
            clock=self._clock,
            senders=self.senders,
            spoofing=self.spoofing,
        )
        self._mirror = TeamMirror(
            bind_host=net.bind_host,
            port=net.mirror_port,
            teams=addresses,
            max_bytes=net.mirror_max_bytes,
            log_dir=self._log_dir,
            spoofing=self.spoofing,
        )
        self._publisher.network = self._network
        self._network.start()
        self._mirror.start()
        self._publish(force=True)

    @property
    def network(self) -> GameControllerNetwork | None:
        return self._network

    @property
    def mirror(self) -> TeamMirror | None:
        return self._mirror

    def close(self) -> None:
        if self._network is not None:
            self._publisher.log_counts(self._last_ms or 0)
            self._network.close()
            self._network = None
            self._publisher.network = None
        if self._mirror is not None:
            self._mirror.close()
            self._mirror = None
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
                self._publisher.log_counts(snapshot.sim_time_ms)
        self._ball_touch(snapshot)
        self._report_spoofing()
        self.play.observe(snapshot, self.view())
        self._goalkeeper_claims()
        if self._finished:
            return commands
        if self._wait_until_s is not None:
            # INITIAL: the GameController's time runs on, this step's before the wait's end
            self.gc.advance_ms(dt_ms)
            dt_ms = 0
            if self._clock.monotonic() < self._wait_until_s:
                self._publish()
                return commands
            action, self._after_wait, self._wait_until_s = self._after_wait, None, None
            if action is not None:
                commands += action(snapshot)
        tick = self.gc.advance_ms(dt_ms)
        commands += self._on_tick(tick, snapshot)
        if self.gc.state is not GameState.INITIAL and not self._finished:
            commands += penalised_robots(self, snapshot, penalised)
        if not self._finished and self._wait_until_s is None:
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
        gc = self.gc
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
            left_team=self.left_team,
            ball_in_play=self.ball_in_play,
            penalised=frozenset(gc.penalised()),
            goalkeepers=keepers,
            field=self.field,
            timing=self.config.timing,
        )

    def pose_on_side(self, team: TeamColor, pose: Pose) -> Pose:
        return pose.on_side(left=team is self.left_team)

    def ball_at(self, x_m: float, y_m: float) -> PlaceBall:
        return PlaceBall(position=(x_m, y_m, self.field.ball_radius_m))

    def ball_away(self) -> PlaceBall:
        """The ball held off the field until SET places it for the kick-off: in INITIAL and READY
        before each period and after a goal, as the league's referee holds it there
        (hlvs_webots referee.py:1762-1768, ``kickoff`` calling ``move_ball_away``)."""
        return self.ball_at(*BALL_AWAY_XY)

    def emit(self, event: RefereeEvent) -> None:
        self.events.append(event)
        self.log.event(event)

    def _wait(self, seconds: float, action: Action, why: str, sim_ms: int) -> None:
        self._wait_until_s = self._clock.monotonic() + seconds
        self._after_wait = action
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
        commands = self._starting_positions(snapshot.sim_time_ms)
        self._placed_at_start_ms = snapshot.sim_time_ms
        if cfg.game_type is GameType.PENALTY:
            self._wait(cfg.timing.wait_before_first_ready_real_s, self._begin_shootout,
                       "before the penalty shoot-out", snapshot.sim_time_ms)
        else:
            self._wait(cfg.timing.wait_before_first_ready_real_s, self._to_ready,
                       "before the first READY", snapshot.sim_time_ms)
        return commands

    def _starting_positions(self, sim_time_ms: int) -> list[WorldCommand]:
        commands: list[WorldCommand] = []
        for color in (TeamColor.RED, TeamColor.BLUE):
            for player in self.config.team(color).players:
                robot = RobotId(color, player.number)
                if robot in self.red_carded:
                    continue
                pose = self.pose_on_side(color, player.half_time_pose)
                self.log.info(
                    sim_time_ms,
                    f"{robot} at halfTimeStartingPose ({pose.x_m:.2f}, {pose.y_m:.2f}, "
                    f"{pose.yaw_rad:.2f}).",
                )
                commands.append(
                    TeleportRobot(robot=robot, pose=pose)
                )
                if robot in self.limp:
                    commands.append(SetLimp(robot=robot, limp=False))
        self.limp.clear()
        commands.append(self.ball_away())
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
        return self._apply(kickoff.judge_start(snapshot, self.view()), snapshot)

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

    def _on_tick(self, tick: Tick, snapshot: WorldSnapshot) -> list[WorldCommand]:
        commands: list[WorldCommand] = []
        now = snapshot.sim_time_ms
        for robot in tick.unpenalised:
            if robot in self.limp:
                self.limp.discard(robot)
                commands.append(SetLimp(robot=robot, limp=False))
            self.log.info(now, f"Penalty of {robot} is over.")
            self.emit(RefereeEvent(sim_time_ms=now, type="unpenalised", team=robot.team,
                                   player=robot.number))
        if tick.auto_set:
            self._set_since_ms = now
            self.state_event(snapshot, "SET")
            commands += self._place_kick_off_ball(snapshot)
            commands += self._apply(kickoff.judge_set(snapshot, self.view()), snapshot)
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
            commands += self._apply(set_play.judge_execute(snapshot, self.view(), play), snapshot)
            restriction = {
                SecondaryState.THROW_IN: goal.Restriction.THROW_IN,
                SecondaryState.INDIRECT_FREEKICK: goal.Restriction.INDIRECT_FREE_KICK,
            }.get(play.kind)
            self.rules.restart(snapshot, restriction, play.team)
        if tick.period_over and self.gc.phase is not SecondaryState.PENALTYSHOOT:
            commands += self._end_period(snapshot)
        return commands

    def _place_kick_off_ball(self, snapshot: WorldSnapshot) -> list[WorldCommand]:
        """SET begins: the ball is put on the centre spot, as the league's referee places it for
        the kick-off (or the dropped ball) when SET begins, wherever a robot pushed it in
        READY."""
        x, y = snapshot.ball.position[0], snapshot.ball.position[1]
        field = self.field
        on_field = abs(x) <= field.turf_half_length_m and abs(y) <= field.turf_half_width_m
        if on_field and math.hypot(x, y) > BALL_ON_SPOT_M:
            self.log.info(snapshot.sim_time_ms, f"Ball moved in READY to ({x:.2f}, {y:.2f}); "
                          "placed on the centre spot.")  # fmt: skip
        return [self.ball_at(0.0, 0.0)]

    def _play_step(self, snapshot: WorldSnapshot) -> list[WorldCommand]:
        gc = self.gc
        now = snapshot.sim_time_ms
        commands: list[WorldCommand] = []
        if gc.state is GameState.SET and self._set_since_ms is not None:
            if now - self._set_since_ms >= self.config.timing.set_to_play_s * 1000.0:
                gc.transition(GameState.PLAYING)
                self._set_since_ms = None
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
        return commands + self._apply(decisions, snapshot)

    def give_card(
        self, robot: RobotId, card: Card, reason: str, snapshot: WorldSnapshot
    ) -> list[WorldCommand]:
        """A card given by hand, as the league's human referee does at the GameController (the
        automatic rules give none). Escalates like every card; a red card removes the robot."""
        return self._apply([GiveCard(robot, card, reason)], snapshot)

    def force_state(self, state: GameState, snapshot: WorldSnapshot) -> list[WorldCommand]:
        """Put the game into ``state`` now, as a trainer may (learning environments): cancels a
        pending wall-clock wait and skips the transitions a match would take. READY goes on to
        SET when its time is up, SET to PLAYING after ``set_to_play_s``; PLAYING starts with the
        ball in play as after a dropped ball's SET. Returns the world commands to apply: the ball
        held off the field before a kick-off is put on the centre spot for SET or PLAYING, as
        SET would have put it."""
        commands: list[WorldCommand] = []
        x, y = snapshot.ball.position[0], snapshot.ball.position[1]
        away = abs(x) > self.field.turf_half_length_m or abs(y) > self.field.turf_half_width_m
        if away and state in (GameState.SET, GameState.PLAYING):
            placed = self.ball_at(0.0, 0.0)
            commands.append(placed)
            snapshot = replace(snapshot, ball=BallState(position=placed.position,
                                                        velocity=(0.0, 0.0, 0.0)))  # fmt: skip
        gc = self.gc
        self._started = True
        self._wait_until_s = None
        self._after_wait = None
        self._set_since_ms = snapshot.sim_time_ms if state is GameState.SET else None
        self.ball_in_play = False
        gc.state = _PREDECESSOR[state]  # a state from which the transition is allowed
        gc.transition(state)
        if state is GameState.PLAYING:
            self.rules.restart(snapshot, None)
        self.log.info(snapshot.sim_time_ms, f"State {state.name} set by the trainer.")
        return commands

    def _apply(self, decisions: list[Decision], snapshot: WorldSnapshot) -> list[WorldCommand]:
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
        self._set_since_ms = None
        self.state_event(snapshot, "FINISHED", next=following.value)
        commands: list[WorldCommand] = [
            SetLimp(robot=r, limp=False) for r in sorted(self.limp, key=str)
        ]
        self.limp.clear()
        if following is end_of_game.Next.FINISHED:
            self._finish(snapshot, end_of_game.winner(score))
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
            commands = self._starting_positions(snapshot.sim_time_ms)
            self._placed_at_start_ms = snapshot.sim_time_ms
            after = self._to_ready
        self._wait(self.config.timing.half_time_break_real_s, after,
                   f"before the {following.value}", snapshot.sim_time_ms)
        return commands

    def _finish(self, snapshot: WorldSnapshot, winner: TeamColor | None) -> None:
        self._finished = True
        self._winner = winner
        red, blue = self.gc.score(TeamColor.RED), self.gc.score(TeamColor.BLUE)
        self.log.info(snapshot.sim_time_ms, f"FINAL SCORE: {red}-{blue}")
        if winner is None:
            self.log.info(snapshot.sim_time_ms, "The game ended in a draw.")
        else:
            self.log.info(snapshot.sim_time_ms, f"The winner is the {winner.value} team.")
        self.emit(
            RefereeEvent(
                sim_time_ms=snapshot.sim_time_ms, type="game_over", team=winner,
                reason="draw" if winner is None else "winner",
                details={"score": {"red": red, "blue": blue}, "coin_toss": self._coin_toss},
            )
        )

    # --- penalty shoot-out ---------------------------------------------------------------

    def _begin_shootout(self, snapshot: WorldSnapshot) -> list[WorldCommand]:
        self._shootout = Shootout(
            config=self.config, first=self.config.kickoff, left=self.left_team
        )
        self.log.info(snapshot.sim_time_ms, "Penalty shoot-out begins.")
        return self._setup_kick(snapshot)

    def _setup_kick(self, snapshot: WorldSnapshot) -> list[WorldCommand]:
        """SET for the next kick. A team with no player to kick loses its turn at once, as
        the league's referee skips it (``next_penalty_shootout``, hlvs_webots referee.py:
        1648-1654): the kick counts as missed and the other team's kick is set up in the
        same SET."""
        assert self._shootout is not None
        shootout = self._shootout
        while True:
            keeper = self.gc.goalkeeper(shootout.attacker.opponent)
            placing = shootout.setup_kick(snapshot, self.red_carded, keeper=keeper)
            if shootout.kicker is not None:
                break
            skipped = KickOutcome(
                shootout.attacker, RobotId(shootout.attacker, 0), False, "no kicker"
            )
            if self._record_kick(snapshot, skipped):
                return []
            shootout.attacker = shootout.attacker.opponent
        self.left_team = shootout.left_team
        self.gc.kickoff_team = shootout.attacker
        self.gc.secs_remaining = self.config.timing.shootout_kick_s
        self.gc.transition(GameState.SET)
        self._set_since_ms = snapshot.sim_time_ms
        # the league's GameController has been FINISHED between the kicks (after a goal, or
        # sent by its referee, hlvs_webots referee.py:1636-1638), which clears every penalty
        for robot in self.gc.penalised():
            self.gc.unpenalize(robot)
        commands: list[WorldCommand] = [
            SetLimp(robot=r, limp=False) for r in sorted(self.limp, key=str)
        ]
        self.limp.clear()
        commands += placing
        self.state_event(snapshot, "SET", kicker=str(shootout.kicker))
        return commands

    def _record_kick(self, snapshot: WorldSnapshot, outcome: KickOutcome) -> bool:
        """Count a kick; True when it decided the shoot-out (the game is then over)."""
        assert self._shootout is not None
        gc = self.gc
        now = snapshot.sim_time_ms
        status = self._shootout.record(gc, outcome, seed=self.config.seed)
        kicks = gc.teams[outcome.team].penalty_shots
        verdict = "scored" if outcome.scored else f"missed ({outcome.reason})"
        self.log.info(now, f"Penalty shoot-out: {outcome.kicker} kick {kicks} {verdict}.")
        self.emit(
            RefereeEvent(
                sim_time_ms=now, type="shootout_kick", team=outcome.team,
                player=outcome.kicker.number, reason=outcome.reason,
                details={"scored": outcome.scored, "kick": kicks},
            )
        )
        if not status.decided:
            return False
        if gc.state is not GameState.FINISHED:
            gc.transition(GameState.FINISHED)
        self._coin_toss = status.coin_toss
        self._finish(snapshot, status.winner)
        return True

    def _shootout_step(self, snapshot: WorldSnapshot) -> list[WorldCommand]:
        if self._shootout is None:
            return []
        gc = self.gc
        now = snapshot.sim_time_ms
        commands: list[WorldCommand] = []
        if gc.state in (GameState.SET, GameState.PLAYING):
            penalized = set(gc.penalised())
            decisions = self._shootout.judge_goalkeeper(snapshot, penalized=penalized)
            commands += self._apply(list(decisions), snapshot)
        if gc.state is GameState.SET and self._set_since_ms is not None:
            if now - self._set_since_ms >= self.config.timing.shootout_set_to_play_s * 1000.0:
                gc.transition(GameState.PLAYING)
                self._set_since_ms = None
                self.state_event(snapshot, "PLAYING")
            return commands
        if gc.state is not GameState.PLAYING:
            return commands
        outcome = self._shootout.judge(snapshot, gc.secs_remaining)
        if outcome is None:
            return commands
        if self._record_kick(snapshot, outcome):
            return []
        self._shootout.attacker = self._shootout.attacker.opponent
        return commands + self._setup_kick(snapshot)

    # --- outputs -------------------------------------------------------------------------

    def _ball_touch(self, snapshot: WorldSnapshot) -> None:
        toucher = snapshot.last_ball_toucher
        if toucher is not None and snapshot.last_ball_touch_ms != self._last_touch_ms:
            if toucher != self._last_toucher or self._last_touch_ms is None:
                self.log.info(snapshot.sim_time_ms, f"Ball touched by {toucher}.")
            self._last_toucher = toucher
            self._last_touch_ms = snapshot.last_ball_touch_ms

    def _report_spoofing(self) -> None:
        """Each new kind of spoofing attempt: one warning and one ``spoofing`` event."""
        for attempt in self.spoofing.take_new():
            sim_ms = self._last_ms or 0
            self.log.warning(sim_ms, attempt.describe() + ".")
            sender = self.senders.robots_at(attempt.sender)
            robot = min(sender, key=robot_key) if len(sender) == 1 else None
            self.emit(RefereeEvent(
                sim_time_ms=sim_ms, type="spoofing",
                team=robot.team if robot is not None else None,
                player=robot.number if robot is not None else None,
                reason=attempt.describe(), details=attempt.to_json(),
            ))

    def _goalkeeper_claims(self) -> None:
        if self._network is None:
            return
        for robot in self._network.take_goalkeeper_claims():
            if robot.number in self.gc.teams[robot.team].robots:
                self.gc.set_goalkeeper(robot)
                self.log.info(self._last_ms or 0, f"{robot} declared itself goalkeeper.")

    def _publish(self, *, force: bool = False) -> None:
        self._publisher.publish(self._last_ms or 0, force=force)

    def packet(self) -> bytes:
        """The current ``RGme`` datagram (``packetNumber`` 0: the sender numbers its packets)."""
        return self._publisher.packet()
