"""The GameController state machine, advanced on simulated time.

It holds what the league GameController holds (state, periods, score, set plays, penalties,
cards, shoot-out shots) and advances its timers when the referee feeds it the simulated time
of each snapshot. It makes no judgement: the AutoRef decides, this machine records and times.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass, field

from contracts import GameType, RobotId, TeamColor
from referee.config import TimingConfig
from referee.errors import IllegalTransition
from referee.gamecontroller.states import (
    ALLOWED_TRANSITIONS,
    Card,
    GameState,
    Penalty,
    SecondaryState,
)

logger = logging.getLogger(__name__)

EPSILON_S = 1e-6  # timers are sums of 8 ms steps in floating point


@dataclass(slots=True)
class RobotStatus:
    """A robot's penalty, cards and role as the GameController keeps them (the wire's
    ``contracts.gamecontroller.RobotInfo`` is built from it each packet)."""

    penalty: Penalty = Penalty.NONE
    secs_till_unpenalised: float = 0.0
    warnings: int = 0
    yellow_cards: int = 0
    red_cards: int = 0
    goalkeeper: bool = False


@dataclass(slots=True)
class TeamStatus:
    """A team's score, shoot-out and robots as the GameController keeps them (the wire's
    ``contracts.gamecontroller.TeamInfo`` is built from it each packet)."""

    score: int = 0
    penalty_shots: int = 0  # shoot-out kicks taken
    single_shots: int = 0  # bit i set: kick i scored
    robots: dict[int, RobotStatus] = field(default_factory=dict)


@dataclass(frozen=True, slots=True)
class SetPlay:
    kind: SecondaryState
    team: TeamColor
    sub_phase: int  # 0 ball placed, robots still; 1 robots position; 2 robots freeze


@dataclass(frozen=True, slots=True)
class Tick:
    """What happened by itself while the timers ran."""

    auto_set: bool = False  # READY time ran out: now SET
    set_play_phase: int | None = None  # the set play moved to this sub-phase
    set_play_executed: SetPlay | None = None  # EXECUTE: secondary state back to NORMAL
    unpenalised: tuple[RobotId, ...] = ()
    period_over: bool = False  # secs_remaining reached 0 while the clock ran


class GameController:
    def __init__(
        self,
        *,
        game_type: GameType,
        players: dict[TeamColor, tuple[int, ...]],
        kickoff: TeamColor,
        timing: TimingConfig,
        goalkeepers: dict[TeamColor, int] | None = None,
    ) -> None:
        self.game_type = game_type
        self.timing = timing
        self.state = GameState.INITIAL
        self.phase = SecondaryState.NORMAL  # NORMAL, OVERTIME or PENALTYSHOOT
        self.half = 1
        self.first_kickoff = kickoff
        self.kickoff_team: TeamColor | None = kickoff  # None: dropped ball
        self.secs_remaining = timing.half_duration_s
        self.secondary_time = 0.0
        self.period_started = False  # a PLAYING of this period began: READY and SET run the clock
        self.set_play: SetPlay | None = None
        self.teams: dict[TeamColor, TeamStatus] = {
            color: TeamStatus(robots={n: RobotStatus() for n in numbers})
            for color, numbers in players.items()
        }
        keepers = goalkeepers or {}
        for color, team in self.teams.items():
            keeper = keepers.get(color, min(team.robots) if team.robots else 0)
            if keeper in team.robots:
                team.robots[keeper].goalkeeper = True
        if game_type is GameType.PENALTY:
            self.phase = SecondaryState.PENALTYSHOOT
            self.secs_remaining = timing.shootout_kick_s

    # --- views ---------------------------------------------------------------------------

    @property
    def secondary_state(self) -> SecondaryState:
        return self.set_play.kind if self.set_play is not None else self.phase

    @property
    def clock_running(self) -> bool:
        """Whether the game clock runs now, as in the league GameController's
        ``AdvancedData.getRemainingGameTime``: it runs in PLAYING; in READY and SET only once a
        PLAYING of this period has begun (``timeBeforeCurrentGameState != 0``), so every period
        starts its first PLAYING with its full time and, after a goal or a dropped ball, READY
        and SET count as played (no added time); in the penalty shoot-out only in PLAYING."""
        if self.state is GameState.PLAYING:
            return True
        if self.state not in (GameState.READY, GameState.SET):
            return False
        return self.period_started and self.phase is not SecondaryState.PENALTYSHOOT

    def score(self, color: TeamColor) -> int:
        return self.teams[color].score

    def robot(self, robot: RobotId) -> RobotStatus:
        return self.teams[robot.team].robots[robot.number]

    def penalised(self) -> tuple[RobotId, ...]:
        return tuple(
            RobotId(color, n)
            for color, team in self.teams.items()
            for n, info in sorted(team.robots.items())
            if info.penalty is not Penalty.NONE
        )

    def goalkeeper(self, color: TeamColor) -> int | None:
        for number, info in sorted(self.teams[color].robots.items()):
            if info.goalkeeper:
                return number
        return None

    # --- state changes -------------------------------------------------------------------

    def transition(self, new_state: GameState) -> None:
        if new_state not in ALLOWED_TRANSITIONS[self.state]:
            raise IllegalTransition(current=self.state.name, requested=new_state.name)
        logger.debug("game state %s -> %s", self.state.name, new_state.name)
        self.state = new_state
        if new_state is GameState.READY:
            self.secondary_time = self.timing.ready_duration_s
            self.set_play = None
        elif new_state is GameState.SET:
            self.secondary_time = 0.0
        elif new_state is GameState.PLAYING:
            self.period_started = True
            self.secondary_time = (
                self.timing.shootout_kick_s
                if self.phase is SecondaryState.PENALTYSHOOT
                else self.timing.kickoff_blocked_s
            )
        elif new_state is GameState.FINISHED:
            self.set_play = None
            self.secondary_time = 0.0
            self.secs_remaining = 0.0  # as the league's GameController shows a finished period
            for team in self.teams.values():
                for info in team.robots.values():
                    if info.red_cards == 0:
                        info.penalty = Penalty.NONE
                        info.secs_till_unpenalised = 0.0

    def goal(self, scoring: TeamColor) -> None:
        """A valid goal: score, kick-off for the conceding team, READY."""
        self.teams[scoring].score += 1
        self.kickoff_team = scoring.opponent
        self.transition(GameState.READY)

    def dropped_ball(self) -> None:
        self.kickoff_team = None
        self.transition(GameState.READY)

    def begin_set_play(self, kind: SecondaryState, team: TeamColor) -> None:
        if not kind.is_set_play:
            raise ValueError(f"{kind.name} is not a set play")
        if self.state is not GameState.PLAYING:
            raise IllegalTransition(current=self.state.name, requested=kind.name)
        self.set_play = SetPlay(kind, team, 0)
        self.secondary_time = self.timing.set_play_phase0_s

    def retake_set_play(self) -> None:
        """RETAKE: the set play in preparation starts again from sub-phase 0."""
        play = self.set_play
        if play is None:
            raise IllegalTransition(current=self.state.name, requested="RETAKE")
        self.begin_set_play(play.kind, play.team)

    def abort_set_play(self) -> None:
        """ABORT: the set play in preparation is cancelled; play goes on."""
        if self.set_play is None:
            raise IllegalTransition(current=self.state.name, requested="ABORT")
        self.set_play = None
        self.secondary_time = 0.0

    def next_period(self) -> SecondaryState:
        """From FINISHED, start the next period; returns its phase. Caller checks it exists."""
        self.transition(GameState.INITIAL)
        self.period_started = False
        if self.phase is SecondaryState.NORMAL and self.half == 1:
            self.half = 2
            self.secs_remaining = self.timing.half_duration_s
            self.kickoff_team = self.first_kickoff.opponent
        elif self.phase is SecondaryState.NORMAL:
            self.phase = SecondaryState.OVERTIME
            self.half = 1
            self.secs_remaining = self.timing.overtime_half_duration_s
            self.kickoff_team = self.first_kickoff
        elif self.phase is SecondaryState.OVERTIME and self.half == 1:
            self.half = 2
            self.secs_remaining = self.timing.overtime_half_duration_s
            self.kickoff_team = self.first_kickoff.opponent
        else:
            self.phase = SecondaryState.PENALTYSHOOT
            self.half = 1
            self.secs_remaining = self.timing.shootout_kick_s
            self.kickoff_team = self.first_kickoff
        return self.phase

    # --- penalties and cards -------------------------------------------------------------

    def penalize(self, robot: RobotId, penalty: Penalty, seconds: float | None = None) -> None:
        info = self.robot(robot)
        info.penalty = penalty
        info.secs_till_unpenalised = self.timing.removal_penalty_s if seconds is None else seconds

    def unpenalize(self, robot: RobotId) -> None:
        info = self.robot(robot)
        if info.red_cards:
            return
        info.penalty = Penalty.NONE
        info.secs_till_unpenalised = 0.0

    def card(self, robot: RobotId, card: Card) -> Card:
        """Record a card; 2 warnings make a yellow, 2 yellows a red. Returns the card given."""
        info = self.robot(robot)
        if card is Card.WARNING:
            info.warnings += 1
            if info.warnings < 2:
                return Card.WARNING
            info.warnings = 0
            card = Card.YELLOW
        if card is Card.YELLOW:
            info.yellow_cards += 1
            if info.yellow_cards < 2:
                return Card.YELLOW
            card = Card.RED
        info.red_cards += 1
        info.penalty = Penalty.SUBSTITUTE
        info.secs_till_unpenalised = 0.0
        return Card.RED

    def set_goalkeeper(self, robot: RobotId) -> None:
        for number, info in self.teams[robot.team].robots.items():
            info.goalkeeper = number == robot.number

    # --- penalty shoot-out ---------------------------------------------------------------

    def shootout_kick(self, team: TeamColor, scored: bool) -> None:
        info = self.teams[team]
        if scored:
            info.single_shots |= 1 << info.penalty_shots
            info.score += 1
        info.penalty_shots += 1

    # --- time ----------------------------------------------------------------------------

    def advance(self, dt_s: float) -> Tick:
        """Run the timers for ``dt_s`` seconds of simulated time."""
        if self.state in (GameState.INITIAL, GameState.FINISHED) or dt_s <= 0:
            return Tick()
        period_over = False
        if self.clock_running:
            before = self.secs_remaining
            self.secs_remaining -= dt_s
            period_over = before > EPSILON_S >= self.secs_remaining
        unpenalised = []
        for color, team in self.teams.items():
            for number, info in sorted(team.robots.items()):
                if info.penalty is Penalty.NONE or info.red_cards:
                    continue
                info.secs_till_unpenalised -= dt_s
                if info.secs_till_unpenalised <= EPSILON_S:
                    info.penalty = Penalty.NONE
                    info.secs_till_unpenalised = 0.0
                    unpenalised.append(RobotId(color, number))
        self.secondary_time = max(0.0, self.secondary_time - dt_s)
        auto_set = False
        phase: int | None = None
        executed: SetPlay | None = None
        if self.state is GameState.READY and self.secondary_time <= EPSILON_S:
            self.transition(GameState.SET)
            auto_set = True
        elif self.set_play is not None and self.secondary_time <= EPSILON_S:
            play = self.set_play
            if play.sub_phase == 0:
                phase = 1
                ready_s = self.timing.set_play_ready_s
                if play.kind is SecondaryState.PENALTYKICK:
                    ready_s *= 2
                self.secondary_time = ready_s
            elif play.sub_phase == 1:
                phase = 2
                self.secondary_time = self.timing.set_play_prepare_s
            if phase is not None:
                self.set_play = SetPlay(play.kind, play.team, phase)
            else:
                executed = play
                self.set_play = None
                self.secondary_time = self.timing.kickoff_blocked_s
        return Tick(
            auto_set=auto_set,
            set_play_phase=phase,
            set_play_executed=executed,
            unpenalised=tuple(unpenalised),
            period_over=period_over,
        )
