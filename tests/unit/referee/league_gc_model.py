"""A transliteration of the league's GameController (Humanoid TC GameController, 2024-master,
``src/data/states/AdvancedData.java`` and the actions the league's referee commands) into a few
lines of Python, to tell what it would send, field by field, when told the same things at the
same simulated times.

It keeps the league's own bookkeeping (milliseconds of the time the referee sends with
``CLOCK``, ``whenCurrentGameStateBegan``, ``timeBeforeCurrentGameState``, the manual pause a set
play sets, ``whenPenalized``, the secondary clock) and computes the packet as ``Sender.run``
does: ``updateTimes`` (which also lifts served penalties), then ``toByteArray``. Only what an
HLVS game uses is here (no timeouts, no drop-in, no coach, no test mode); the rules are the
simulation leagues' (``HLSim.java``) with the durations a test shortens passed in.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from contracts.gamecontroller import (
    DROP_IN_TIME_NONE,
    MAX_PLAYERS,
    GameControlData,
    RobotInfo,
    TeamInfo,
)

INITIAL, READY, SET, PLAYING, FINISHED = 0, 1, 2, 3, 4
NORMAL, PENALTYSHOOT, OVERTIME = 0, 1, 2
INTERRUPTIONS = range(4, 10)  # DIRECT_FREEKICK .. THROW_IN
NONE, SUBSTITUTE, MANUAL = 0, 14, 15
PENALTY_TIME_S = {0: -1, 30: 30, 31: 30, 34: 30, 35: 60}  # Penalties.java:10, 15-18
DROPBALL = 128


@dataclass(frozen=True, slots=True)
class LeagueRules:
    """``HLSim.java`` values; a test shortens the READY and the half as game.json does."""

    half_time_s: int = 600  # :34 (or --halftimeduration)
    ready_time_s: int = 45  # :36
    pause_time_s: int = 0  # :38
    kickoff_time_s: int = 10  # :44
    blocked_after_game_interruption_s: int = 10  # :46
    game_interruption_preparation_time_s: int = 15  # :114
    team_size: int = 4  # HLSimulationKid.java:17 (ADULT: 2)


@dataclass(slots=True)
class _Player:
    penalty: int = NONE
    secs_till_unpenalised: int = 0
    is_goalie: bool = False
    when_penalized: int = 0
    serving: bool = False


@dataclass(slots=True)
class _Team:
    number: int
    colour: int
    score: int = 0
    players: list[_Player] = field(default_factory=list)


class LeagueGameController:
    def __init__(self, rules: LeagueRules, *, left: tuple[int, int], right: tuple[int, int],
                 kickoff: int, game_type: int = 0) -> None:  # fmt: skip
        """``left``/``right``: (team number, colour) of ``team[0]`` and ``team[1]`` once the
        referee's SIDE_LEFT is done; ``kickoff``: the team number its KICKOFF names."""
        self.rules = rules
        self.system_ms = 0  # SystemClock.setTime (the referee's CLOCK)
        self.game_type = game_type
        self.state = INITIAL
        self.first_half = True
        self.kickoff_team = kickoff
        self.left_side_kickoff = kickoff == left[0]  # KickOff.java (kickoffChoice, INITIAL)
        self.sec_state = NORMAL
        self.previous_sec_state = NORMAL
        self.info = [0, 0, 0, 0]
        self.team = [self._team(*left), self._team(*right)]
        self.time_before_current_state = 0
        self.when_state_began = 0
        self.when_secondary_ended = 0
        self.man_pause = False
        self.man_when_clock_changed = 0
        self.man_time_offset = 0
        self.secondary_clock_start: int | None = None  # GameClock.secondaryClock (ExtraClock)

    def _team(self, number: int, colour: int) -> _Team:
        players = [_Player() for _ in range(MAX_PLAYERS)]
        for j, player in enumerate(players):
            if j >= self.rules.team_size:  # AdvancedData.java:144
                player.penalty = SUBSTITUTE
        players[0].is_goalie = True  # GameControllerSimulator.java:366-369, MakeGoalieAction 0
        return _Team(number, colour, players=players)

    # --- AdvancedData's time -----------------------------------------------------------

    def get_time(self) -> int:  # AdvancedData.java:191
        return self.man_when_clock_changed if self.man_pause else (
            self.system_ms + self.man_time_offset)

    def seconds_since(self, millis: int) -> int:  # AdvancedData.java:201 (int division)
        return 100000 if millis == 0 else int((self.get_time() - millis) / 1000)

    def clock_running(self) -> bool:  # ClockTick.java:69
        half_not_started = self.time_before_current_state == 0 and self.state != PLAYING
        return not (self.state in (INITIAL, FINISHED)
                    or (self.state in (READY, SET) and half_not_started)
                    or self.man_pause)  # fmt: skip

    def remaining_game_time(self) -> int:  # AdvancedData.java:282 (real false, HL rules)
        duration = self.rules.half_time_s
        if self.state in (INITIAL, FINISHED) or (
                self.state in (READY, SET) and self.time_before_current_state == 0):
            played = int(self.time_before_current_state / 1000)
        else:
            played = self.seconds_since(self.when_state_began - self.time_before_current_state)
        return duration - played

    def remaining_pause_time(self) -> int | None:  # AdvancedData.java:307
        if self.sec_state in (NORMAL, OVERTIME) and (
                (self.state == INITIAL and not self.first_half)
                or (self.state == FINISHED and self.first_half)):
            return self.rules.pause_time_s - self.seconds_since(self.when_state_began)
        return None

    def secondary_time(self) -> int | None:  # AdvancedData.java:421, getSecondaryTime(0)
        if self.sec_state in INTERRUPTIONS:
            if self.secondary_clock_start is None:
                return None
            since = int((self.system_ms - self.secondary_clock_start) / 1000)  # ExtraClock:25
            return self.rules.game_interruption_preparation_time_s - since
        kickoff_blocked = self.rules.kickoff_time_s - self.seconds_since(self.when_state_began)
        free_kick_blocked = (self.rules.blocked_after_game_interruption_s
                             - self.seconds_since(self.when_secondary_ended))
        if self.kickoff_team == DROPBALL:
            kickoff_blocked = 0
        if self.state == READY:
            return self.rules.ready_time_s - self.seconds_since(self.when_state_began)
        if self.state == PLAYING and self.sec_state != PENALTYSHOOT and kickoff_blocked >= 0:
            return kickoff_blocked if kickoff_blocked > 0 else None
        if self.state == PLAYING and free_kick_blocked >= 0:
            return free_kick_blocked if free_kick_blocked > 0 else None
        return self.remaining_pause_time()

    def remaining_penalty_time(self, player: _Player) -> int:  # AdvancedData.java:373
        if player.penalty in (MANUAL, SUBSTITUTE):
            return 0
        penalty_time = PENALTY_TIME_S[player.penalty]
        if not player.serving:
            return penalty_time
        return max(0, penalty_time - self.seconds_since(player.when_penalized))

    # --- actions (ActionBoard) -----------------------------------------------------------

    def clock(self, ms: int) -> None:  # CLOCK:<ms>
        self.system_ms = ms

    def add_time_in_current_state(self) -> None:  # AdvancedData.java:270
        self.time_before_current_state += self.get_time() - self.when_state_began

    def ready(self) -> None:  # state/Ready.java
        if self.state == READY:
            return
        if self.state == PLAYING:
            self.add_time_in_current_state()
        self.when_state_began = self.get_time()
        self.state = READY

    def set(self) -> None:  # state/Set.java (outside the shoot-out)
        if self.state == SET:
            return
        if self.time_before_current_state != 0:
            self.add_time_in_current_state()
        self.when_state_began = self.get_time()
        self.state = SET

    def play(self) -> None:  # STATE:PLAY, SimulatorUpdateComponent.java:337-346
        if self.state == PLAYING:
            return
        if self.time_before_current_state != 0:  # state/Play.java
            self.add_time_in_current_state()
        self.when_state_began = self.get_time()
        self.state = PLAYING
        if self.sec_state != PENALTYSHOOT:  # resetPenaltyTimes, resetPenalties
            for team in self.team:
                for player in team.players:
                    if player.penalty != SUBSTITUTE:
                        player.penalty = NONE
                    player.when_penalized = 0

    def finish(self) -> None:  # state/Finish.java
        if self.state == FINISHED:
            return
        self.add_time_in_current_state()
        self.when_state_began = self.get_time()
        self.state = FINISHED

    def second_half(self) -> None:  # half/SecondHalf.java, from ClockTick.java:44-45
        self.first_half = False
        self.sec_state = NORMAL
        self.team.reverse()  # AdvancedData.changeSide
        self.time_before_current_state = 0
        for team in self.team:  # resetPenalties
            for player in team.players:
                if player.penalty != SUBSTITUTE:
                    player.penalty = NONE
                player.when_penalized = 0
        self.kickoff_team = self.team[0 if self.left_side_kickoff else 1].number  # :41
        self.state = INITIAL  # whenCurrentGameStateBegan kept: it counts the pause

    def goal(self, side: int) -> None:  # Goal.java (outside the shoot-out)
        for team in self.team:  # clearPenaltiesServed
            for player in team.players:
                if player.serving and self.remaining_penalty_time(player) == 0:
                    player.serving = False
                    player.penalty = NONE
        self.team[side].score += 1
        self.kickoff_team = self.team[1 - side].number
        self.ready()

    def clock_pause(self) -> None:  # ClockPause.java:32 (not in test mode: no manPlay)
        if self.clock_running():
            self.man_when_clock_changed = self.get_time()
            self.man_pause = True
        elif self.man_pause:
            self.man_pause = False
            self.man_time_offset -= self.get_time() - self.man_when_clock_changed

    def game_interruption(self, side: int, kind: int) -> None:  # GameInterruption.java:50
        active = self.sec_state == kind and self.info[0] == self.team[side].number
        if not active:
            self.previous_sec_state = self.sec_state
            self.sec_state = kind
            self.info = [self.team[side].number, 0, 0, 0]
            self.clock_pause()
            return
        sub_mode = self.info[1]
        if sub_mode == 0:
            self.secondary_clock_start = self.system_ms
            self.info = [self.info[0], 1, 0, 0]
        elif sub_mode == 1:
            self.secondary_clock_start = None
            self.info = [self.info[0], 2, 0, 0]
        else:
            self.sec_state, self.previous_sec_state = self.previous_sec_state, kind
            self.info = [0, 0, 0, 0]
            self.when_secondary_ended = self.get_time()
            self.clock_pause()

    def penalty(self, side: int, number: int, code: int) -> None:
        """PENALTY:<team>:<number>:<kind> (SimulatorUpdateComponent.java:285-313)."""
        player = self.team[side].players[number - 1]
        player.penalty = code
        player.when_penalized = self.get_time()
        player.serving = True

    # --- Sender.run ----------------------------------------------------------------------

    def packet(self) -> GameControlData:
        """``updateTimes`` (AdvancedData.java:222), then the fields ``toByteArray`` writes."""
        secs_remaining = self.remaining_game_time()
        secondary = self.secondary_time()
        for team in self.team:
            for player in team.players:
                if player.penalty == NONE:
                    player.secs_till_unpenalised = 0
                    continue
                player.secs_till_unpenalised = self.remaining_penalty_time(player)
                if player.secs_till_unpenalised == 0 and player.penalty not in (MANUAL,
                                                                                 SUBSTITUTE):
                    player.penalty = NONE
        return GameControlData(
            packet_number=0,
            players_per_team=self.rules.team_size,
            game_type=self.game_type,
            state=self.state,
            first_half=self.first_half,
            kick_off_team=self.kickoff_team,
            secondary_state=self.sec_state,
            secondary_state_info=(self.info[0], self.info[1], self.info[2], self.info[3]),
            secs_remaining=secs_remaining,
            secondary_time=0 if secondary is None else secondary,
            drop_in_time=DROP_IN_TIME_NONE,
            teams=(self._team_info(self.team[0]), self._team_info(self.team[1])),
        )

    @staticmethod
    def _team_info(team: _Team) -> TeamInfo:
        return TeamInfo(
            team_number=team.number, team_colour=team.colour, score=team.score,
            players=tuple(
                RobotInfo(penalty=p.penalty, secs_till_unpenalised=p.secs_till_unpenalised,
                          goal_keeper=p.is_goalie)
                for p in team.players
            ),
        )  # fmt: skip
