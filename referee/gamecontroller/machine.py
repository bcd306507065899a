"""The GameController state machine, advanced on simulated time.

It holds what the league GameController holds (state, periods, score, set plays, penalties,
cards, shoot-out shots) and advances its timers when the referee feeds it the simulated time
of each snapshot. It makes no judgement: the AutoRef decides, this machine records and times.

Time is counted in whole milliseconds of simulated time (the league's GameController counts
milliseconds of the time its referee sends, ``SystemClock.setTime``), so that the seconds on the
wire are exact: a half of 600 s shows 600 until 1000 ms have been played, then 599
(``AdvancedData.getSecondsSince``: ``(int) (getTime() - millis) / 1000``). Two clocks run:

- the simulated time itself (the league's ``SystemClock``), which drives the set plays'
  preparation clock (``ExtraClock``);
- the GameController's own time (the league's ``AdvancedData.getTime()``), which stands still
  while a set play is prepared: ``GameInterruption.java:60`` pauses it at the interruption
  (``ClockPause``, ``AdvancedData.getTime`` returns the moment of the pause) and
  ``GameInterruption.java:81`` runs it again at EXECUTE. The game clock, the penalties and the
  times since a state began all read this time.
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

PAUSE_S = 0
"""The league's ``pauseTime`` and ``pauseOverTime`` in the simulation leagues (``HLSim.java:38``,
``:40``): the secondary time of a half-time INITIAL counts down from 0 into negative values."""


def to_ms(seconds: float) -> int:
    """Seconds of a configured duration as whole milliseconds."""
    return round(seconds * 1000.0)


def wire_seconds(ms: int) -> int:
    """Whole seconds left of ``ms`` milliseconds as the league's GameController shows them: a
    duration of ``d`` s after ``e`` ms shows ``d - e // 1000`` (``getRemainingSeconds``), that
    is ``ms / 1000`` rounded up, exactly, in integers."""
    return -(-ms // 1000)


@dataclass(slots=True)
class RobotStatus:
    """A robot's penalty, cards and role as the GameController keeps them (the wire's
    ``contracts.gamecontroller.RobotInfo`` is built from it each packet)."""

    penalty: Penalty = Penalty.NONE
    left_ms: int = 0  # of the penalty, on the GameController's time
    warnings: int = 0
    yellow_cards: int = 0
    red_cards: int = 0
    goalkeeper: bool = False

    @property
    def secs_till_unpenalised(self) -> float:
        return self.left_ms / 1000.0


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


def reset_penalties(teams: dict[TeamColor, TeamStatus]) -> tuple[RobotId, ...]:
    """``AdvancedData.resetPenalties`` (``AdvancedData.java:342-365``): every penalty but
    SUBSTITUTE lifted, a sent-off robot's too (its red card stays). Returns the robots."""
    lifted = []
    for color, team in teams.items():
        for number, info in sorted(team.robots.items()):
            if info.penalty not in (Penalty.NONE, Penalty.SUBSTITUTE):
                info.penalty = Penalty.NONE
                info.left_ms = 0
                lifted.append(RobotId(color, number))
    return tuple(lifted)


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
        self._remaining_ms = to_ms(timing.half_duration_s)  # of the game clock
        self._timer_ms = 0  # the referee's own countdown: READY, set-play sub-phases, blocked
        self.period_started = False  # a PLAYING of this period began: READY and SET run the clock
        self.set_play: SetPlay | None = None
        self.clock_paused = False  # a set play is prepared: the GameController's time stands
        self.sim_ms = 0  # simulated time fed so far (the league's SystemClock)
        self.gc_ms = 0  # the GameController's own time (the league's AdvancedData.getTime)
        self._state_began_gc_ms = 0  # whenCurrentGameStateBegan
        self._set_play_ended_gc_ms: int | None = None  # whenCurrentSecondaryGameStateEnded
        self._preparation_began_sim_ms: int | None = None  # the set play's secondary clock
        self.revision = 0  # + 1 at each card, goalkeeper and shoot-out kick (wire_values)
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
            self._remaining_ms = to_ms(timing.shootout_kick_s)

    # --- views ---------------------------------------------------------------------------

    @property
    def secs_remaining(self) -> float:
        """Seconds left on the game clock (the wire shows :meth:`wire_secs_remaining`)."""
        return self._remaining_ms / 1000.0

    @secs_remaining.setter
    def secs_remaining(self, seconds: float) -> None:
        self._remaining_ms = to_ms(seconds)

    @property
    def secondary_time(self) -> float:
        """Seconds left on the referee's own countdown: READY, the set play's sub-phase, the
        ball blocked after a kick-off or a set play (the wire shows
        :meth:`wire_secondary_time`, the league's)."""
        return self._timer_ms / 1000.0

    @property
    def secondary_state(self) -> SecondaryState:
        return self.set_play.kind if self.set_play is not None else self.phase

    @property
    def clock_running(self) -> bool:
        """Whether the game clock runs now, as in the league GameController's
        ``AdvancedData.getRemainingGameTime``: it runs in PLAYING; in READY and SET only once a
        PLAYING of this period has begun (``timeBeforeCurrentGameState != 0``), so every period
        starts its first PLAYING with its full time and, after a goal or a dropped ball, READY
        and SET count as played (no added time); in the penalty shoot-out only in PLAYING.
        It stands still while a set play is prepared (``GameInterruption.java:60``)."""
        if self.clock_paused:
            return False
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

    # --- the wire's times, as the league's GameController computes them ------------------

    def wire_secs_remaining(self) -> int:
        """``secsRemaining``: the half's seconds less the whole seconds played
        (``AdvancedData.java:282`` ``getRemainingGameTime``), exact in integer milliseconds."""
        return wire_seconds(self._remaining_ms)

    def wire_secondary_time(self) -> int:
        """``secondaryTime`` as ``AdvancedData.java:421`` ``getSecondaryTime(0)`` computes it
        (``updateTimes``, ``AdvancedData.java:226-231``: no secondary time is 0):

        - in a set play, the secondary clock: none in sub-phases 0 and 2
          (``GameInterruption.java:57``, ``:72``), in sub-phase 1 the preparation time counting
          down on simulated time, negative once over (``GameInterruption.java:68``,
          ``ExtraClock.getRemainingSeconds``);
        - in READY, the READY time left (``:444``);
        - in PLAYING outside the shoot-out, the kick-off's blocked time while positive (none
          after a dropped ball, ``:435``), then (``:453``) the ten seconds after a set play's
          EXECUTE (``whenCurrentSecondaryGameStateEnded``);
        - otherwise the pause (``getRemainingPauseTime``, ``:307``): in the INITIAL before a
          second half and in a first half's FINISHED, ``pauseTime`` (0 s) less the seconds
          since, so it counts 0, -1, -2...; else none."""
        if self.set_play is not None:
            began = self._preparation_began_sim_ms
            if began is None:
                return 0
            return wire_seconds(to_ms(self.timing.set_play_ready_s) - (self.sim_ms - began))
        since_state_ms = self.gc_ms - self._state_began_gc_ms
        if self.state is GameState.READY:
            return wire_seconds(to_ms(self.timing.ready_duration_s) - since_state_ms)
        if self.state is GameState.PLAYING:
            blocked_ms = to_ms(self.timing.kickoff_blocked_s)
            if self.phase is not SecondaryState.PENALTYSHOOT:
                kickoff = 0 if self.kickoff_team is None else wire_seconds(
                    blocked_ms - since_state_ms)
                if kickoff >= 0:
                    return kickoff
            ended = self._set_play_ended_gc_ms
            if ended is not None:
                free_kick = wire_seconds(blocked_ms - (self.gc_ms - ended))
                if free_kick >= 0:
                    return free_kick
            return 0
        pause = (
            self.phase is not SecondaryState.PENALTYSHOOT
            and (
                (self.state is GameState.INITIAL and self.half == 2)
                or (self.state is GameState.FINISHED and self.half == 1)
            )
        )
        return wire_seconds(to_ms(PAUSE_S) - since_state_ms) if pause else 0

    def wire_values(self) -> tuple[int, ...]:
        """The values on the wire that change without a change of state, score or penalties:
        the times (``secsRemaining``, ``secondaryTime``, each penalised robot's seconds), the
        cards, the goalkeepers and the shoot-out's kicks. The packet must be built again when
        they change."""
        return (
            self.wire_secs_remaining(),
            self.wire_secondary_time(),
            self.revision,
            *(
                wire_seconds(info.left_ms)
                for team in self.teams.values()
                for info in team.robots.values()
                if info.penalty is not Penalty.NONE
            ),
        )

    # --- state changes -------------------------------------------------------------------

    def transition(self, new_state: GameState) -> None:
        if new_state not in ALLOWED_TRANSITIONS[self.state]:
            raise IllegalTransition(current=self.state.name, requested=new_state.name)
        logger.debug("game state %s -> %s", self.state.name, new_state.name)
        self.state = new_state
        self._state_began_gc_ms = self.gc_ms
        if new_state is GameState.READY:
            self._timer_ms = to_ms(self.timing.ready_duration_s)
            self._end_set_play()
        elif new_state is GameState.SET:
            self._timer_ms = 0
        elif new_state is GameState.PLAYING:
            self.period_started = True
            self._timer_ms = to_ms(
                self.timing.shootout_kick_s
                if self.phase is SecondaryState.PENALTYSHOOT
                else self.timing.kickoff_blocked_s
            )
        elif new_state is GameState.FINISHED:
            self._end_set_play()
            self._timer_ms = 0
            self._remaining_ms = 0  # as the league's GameController shows a finished period
            reset_penalties(self.teams)  # STATE:FINISH, SimulatorUpdateComponent.java:348-352

    def play(self) -> tuple[RobotId, ...]:
        """SET to PLAYING, as the league's referee commands it (``STATE:PLAY``, hlvs_webots
        referee.py:2366-2368, 2451-2452): the league's GameController then lifts every penalty
        but SUBSTITUTE, served or not, outside the penalty shoot-out
        (``SimulatorUpdateComponent.java:337-346``: ``resetPenaltyTimes``, ``resetPenalties``),
        so that a robot removed in READY or SET plays from the kick-off. Returns the robots
        whose penalty was lifted."""
        self.transition(GameState.PLAYING)
        if self.phase is SecondaryState.PENALTYSHOOT:
            return ()
        return reset_penalties(self.teams)

    def _end_set_play(self) -> None:
        """A set play in preparation ends without EXECUTE (a goal, a dropped ball, the end of
        the period): the GameController's time runs again."""
        self.set_play = None
        self.clock_paused = False
        self._preparation_began_sim_ms = None

    def goal(self, scoring: TeamColor) -> None:
        """A valid goal: score, kick-off for the conceding team, READY."""
        self.teams[scoring].score += 1
        self.kickoff_team = scoring.opponent
        self.transition(GameState.READY)

    def dropped_ball(self) -> None:
        self.kickoff_team = None
        self.transition(GameState.READY)

    def begin_set_play(self, kind: SecondaryState, team: TeamColor) -> None:
        """The interruption: sub-phase 0, no secondary clock, and the GameController's time
        stops (``GameInterruption.java:55-60``, ``ClockPause``)."""
        if not kind.is_set_play:
            raise ValueError(f"{kind.name} is not a set play")
        if self.state is not GameState.PLAYING:
            raise IllegalTransition(current=self.state.name, requested=kind.name)
        self.set_play = SetPlay(kind, team, 0)
        self._timer_ms = to_ms(self.timing.set_play_phase0_s)
        self._preparation_began_sim_ms = None
        self.clock_paused = True

    def retake_set_play(self) -> None:
        """RETAKE: the set play in preparation starts again from sub-phase 0, its secondary
        clock cleared, the time still stopped (``RetakeGameInterruption.java``)."""
        play = self.set_play
        if play is None:
            raise IllegalTransition(current=self.state.name, requested="RETAKE")
        self.begin_set_play(play.kind, play.team)

    def abort_set_play(self) -> None:
        """ABORT: the set play in preparation is cancelled; play goes on and the time runs
        again (``AbortGameInterruption.java``)."""
        if self.set_play is None:
            raise IllegalTransition(current=self.state.name, requested="ABORT")
        self._end_set_play()
        self._timer_ms = 0

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
        info.left_ms = to_ms(self.timing.removal_penalty_s if seconds is None else seconds)

    def unpenalize(self, robot: RobotId) -> None:
        info = self.robot(robot)
        info.penalty = Penalty.NONE
        info.left_ms = 0

    def card(self, robot: RobotId, card: Card) -> Card:
        """Record a card; 2 warnings make a yellow, 2 yellows a red, each count back to 0 as it
        makes the next (``CardIncrease.java:28-64``). Returns the card given. A card leaves the
        penalty as it is: the league's referee sends the penalty with the card and its
        GameController keeps it, a red card's too (hlvs_webots referee.py:1438-1448)."""
        info = self.robot(robot)
        self.revision += 1
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
            info.yellow_cards = 0
            card = Card.RED
        info.red_cards = 1
        return Card.RED

    def set_goalkeeper(self, robot: RobotId) -> None:
        self.revision += 1
        for number, info in self.teams[robot.team].robots.items():
            info.goalkeeper = number == robot.number

    # --- penalty shoot-out ---------------------------------------------------------------

    def shootout_kick(self, team: TeamColor, scored: bool) -> None:
        info = self.teams[team]
        self.revision += 1
        if scored:
            info.single_shots |= 1 << info.penalty_shots
            info.score += 1
        info.penalty_shots += 1

    # --- time ----------------------------------------------------------------------------

    def advance(self, dt_s: float) -> Tick:
        """Run the timers for ``dt_s`` seconds of simulated time (whole milliseconds)."""
        return self.advance_ms(to_ms(dt_s))

    def advance_ms(self, dt_ms: int) -> Tick:
        """Run the timers for ``dt_ms`` milliseconds of simulated time. The GameController's
        own time, and with it the game clock and the penalties, stands still while a set play
        is prepared; the referee's countdowns (READY, the set play's sub-phases) run on."""
        if dt_ms <= 0:
            return Tick()
        self.sim_ms += dt_ms
        if not self.clock_paused:
            self.gc_ms += dt_ms
        if self.state in (GameState.INITIAL, GameState.FINISHED):
            return Tick()
        period_over = False
        if self.clock_running:
            before = self._remaining_ms
            self._remaining_ms -= dt_ms
            period_over = before > 0 >= self._remaining_ms
        unpenalised = []
        if not self.clock_paused:
            for color, team in self.teams.items():
                for number, info in sorted(team.robots.items()):
                    if info.penalty in (Penalty.NONE, Penalty.SUBSTITUTE):
                        continue
                    info.left_ms -= dt_ms
                    if info.left_ms <= 0:
                        info.penalty = Penalty.NONE
                        info.left_ms = 0
                        unpenalised.append(RobotId(color, number))
        self._timer_ms = max(0, self._timer_ms - dt_ms)
        auto_set = False
        phase: int | None = None
        executed: SetPlay | None = None
        if self.state is GameState.READY and self._timer_ms <= 0:
            self.transition(GameState.SET)
            auto_set = True
        elif self.set_play is not None and self._timer_ms <= 0:
            play = self.set_play
            if play.sub_phase == 0:
                phase = 1
                ready_s = self.timing.set_play_ready_s
                if play.kind is SecondaryState.PENALTYKICK:
                    ready_s *= 2
                self._timer_ms = to_ms(ready_s)
                self._preparation_began_sim_ms = self.sim_ms  # GameInterruption.java:68
            elif play.sub_phase == 1:
                phase = 2
                self._timer_ms = to_ms(self.timing.set_play_prepare_s)
                self._preparation_began_sim_ms = None  # GameInterruption.java:72
            if phase is not None:
                self.set_play = SetPlay(play.kind, play.team, phase)
            else:
                executed = play
                self._end_set_play()  # GameInterruption.java:76-81: the time runs again
                self._set_play_ended_gc_ms = self.gc_ms
                self._timer_ms = to_ms(self.timing.kickoff_blocked_s)
        return Tick(
            auto_set=auto_set,
            set_play_phase=phase,
            set_play_executed=executed,
            unpenalised=tuple(unpenalised),
            period_over=period_over,
        )
