"""A captured match against the league's GameController: a removal penalty, a throw-in, a goal
and a half time played by our referee on simulated time, and every ``RGme`` it would send (the
packet after each 8 ms step, decoded with the league's layout) compared field by field with
what the league's GameController sends when its referee commands the same things at the same
simulated times (:mod:`tests.unit.referee.league_gc_model`, a transliteration of its Java).

The model is told only what the league's referee would tell it (SIDE_LEFT and KICKOFF at the
start, CLOCK every step, STATE, SCORE, PENALTY, the set play's steps), read off our packets'
state, score, penalty codes and set-play sub-phase; every time on the wire, the kick-off team,
the player slots, the team order and the sides after half time are the model's own."""

from __future__ import annotations

from dataclasses import replace

from contracts.gamecontroller import GameControlData, decode_game_state
from contracts.ids import RobotId
from referee import FakeClock, PlaceBall, Referee, TeleportRobot
from referee.config import TimingConfig
from referee.gamecontroller import GameState, Penalty
from referee.snapshot import RobotState
from tests.unit.referee.league_gc_model import (
    FINISHED,
    INITIAL,
    INTERRUPTIONS,
    PLAYING,
    READY,
    SET,
    LeagueGameController,
    LeagueRules,
)
from tests.unit.referee.referee_helpers import BLUE, RED, make_config, robot, snapshot

RED_ID, BLUE_ID = 8, 25
RED_COLOUR, BLUE_COLOUR = 1, 0
STEP_MS = 8
TIMING = TimingConfig(
    half_duration_s=40.0,
    ready_duration_s=5.0,
    set_to_play_s=1.0,
    wait_before_first_ready_real_s=1.0,  # the league's CLOCK is never 0 at READY
    half_time_break_real_s=3.0,
    fallen_s=2.0,
)  # the league's durations otherwise: set plays 5 + 15 + 5 s, removal 30 s, blocked 10 s


class Match:
    """Our referee stepped on simulated time (the wall clock along), the ball where the
    referee puts it or where the script moves it."""

    def __init__(self) -> None:
        self.clock = FakeClock()
        self.ref = Referee(config=make_config(timing=TIMING), clock=self.clock)
        self.ms = 0
        self.ball = (0.0, 0.0, 0.07)
        self.fallen_blue_2 = True  # from the start: removed in READY, 2 s later
        self.carried: dict[RobotId, tuple[float, float]] = {}

    def step(self, *, touch: RobotId | None = None, ball: tuple[float, float] | None = None,
             toucher: RobotId | None = None) -> GameControlData:  # fmt: skip
        if ball is not None:
            self.ball = (ball[0], ball[1], 0.07)
        bx, by = self.ball[0], self.ball[1]
        robots: tuple[RobotState, ...] = (
            robot(RED, 1, bx - 0.15, by, ball_contact=True) if touch == RobotId(RED, 1)
            else robot(RED, 1, -2.0, 0.5),
            robot(RED, 2, -1.0, -1.5),
            robot(BLUE, 1, bx + 0.15, by, ball_contact=True) if touch == RobotId(BLUE, 1)
            else robot(BLUE, 1, 2.0, -0.5),
            robot(BLUE, 2, 1.0, 1.5, fallen=self.fallen_blue_2),
        )  # fmt: skip
        # a penalised robot stands where the referee carried it, off the field
        robots = tuple(
            replace(r, position=(*self.carried[r.id], 0.3))
            if r.id in self.carried and self.ref.gc.robot(r.id).penalty is not Penalty.NONE
            else r
            for r in robots
        )
        for command in self.ref.step(snapshot(self.ms, robots, ball=self.ball, toucher=toucher)):
            if isinstance(command, PlaceBall):
                self.ball = command.position
            if isinstance(command, TeleportRobot):
                self.carried[command.robot] = (command.pose.x_m, command.pose.y_m)
        if self.ref.gc.robot(RobotId(BLUE, 2)).penalty is not Penalty.NONE:
            self.fallen_blue_2 = False  # carried off, stands up
        self.ms += STEP_MS
        self.clock.advance(STEP_MS / 1000.0)
        return decode_game_state(self.ref.packet())


def _side(model: LeagueGameController, team_number: int) -> int:
    return 0 if model.team[0].number == team_number else 1


def _command(model: LeagueGameController, before: GameControlData, now: GameControlData) -> None:
    """What the league's referee sends its GameController for the change ``before`` ->
    ``now`` of our packets (state, score, penalty codes, set-play steps)."""
    for old, new in zip(before.teams, now.teams, strict=True):
        for number, (p, q) in enumerate(zip(old.players, new.players, strict=True), start=1):
            if p.penalty == 0 and q.penalty not in (0, 14):
                model.penalty(_side(model, new.team_number), number, q.penalty)
    if before.secondary_state != now.secondary_state or (
            before.secondary_state_info[1] != now.secondary_state_info[1]):
        play = now if now.secondary_state in INTERRUPTIONS else before
        model.game_interruption(_side(model, play.secondary_state_info[0]),
                                play.secondary_state)  # fmt: skip
    if before.first_half and not now.first_half:  # the half ended: FINISH, then the 2nd half
        model.finish()
        model.second_half()
        return
    if now.state == before.state:
        return
    if now.state == READY:
        scorer = next((t.team_number for t, o in zip(now.teams, before.teams, strict=True)
                       if t.score > o.score), None)  # fmt: skip
        if scorer is None:
            model.ready()
        else:
            model.goal(_side(model, scorer))
    elif now.state == SET:
        model.set()
    elif now.state == PLAYING:
        model.play()
    elif now.state == FINISHED:
        model.finish()


def _differences(ours: GameControlData, league: GameControlData) -> list[str]:
    ours = replace(ours, packet_number=0)
    out = [f"{name}: ours {getattr(ours, name)!r}, league {getattr(league, name)!r}"
           for name in ("players_per_team", "game_type", "state", "first_half", "kick_off_team",
                        "secondary_state", "secondary_state_info", "secs_remaining",
                        "secondary_time", "drop_in_team", "drop_in_time")
           if getattr(ours, name) != getattr(league, name)]  # fmt: skip
    for i, (a, b) in enumerate(zip(ours.teams, league.teams, strict=True)):
        if a != b:
            out.append(f"teams[{i}]: ours {a!r}, league {b!r}")
    return out


def test_every_field_of_every_packet_equals_the_leagues() -> None:
    match = Match()
    rules = LeagueRules(half_time_s=40, ready_time_s=5)
    model = LeagueGameController(rules, left=(RED_ID, RED_COLOUR), right=(BLUE_ID, BLUE_COLOUR),
                                 kickoff=RED_ID)  # fmt: skip
    seen: set[str] = set()
    mismatches: list[str] = []
    before: GameControlData | None = None
    playing_since: int | None = None
    throw_in_done_ms: int | None = None
    while match.ms <= 90_000:
        gc = match.ref.gc
        kwargs: dict[str, object] = {}
        if gc.state is GameState.PLAYING and gc.half == 1 and playing_since is None:
            playing_since = match.ms
        started = playing_since is not None and match.ms >= playing_since + 5000
        if started and "throw-in" not in seen:
            kwargs = {"ball": (1.0, 3.3)}  # over blue's touch line, nobody touched it
            seen.add("throw-in")
        elif "throw-in" in seen and throw_in_done_ms is None and gc.set_play is None:
            throw_in_done_ms = match.ms
        elif throw_in_done_ms is not None and "goal" not in seen:
            since = match.ms - throw_in_done_ms
            if since == 3000:
                kwargs = {"touch": RobotId(RED, 1), "toucher": RobotId(RED, 1)}
            elif since == 3008:
                kwargs = {"touch": RobotId(BLUE, 1), "toucher": RobotId(BLUE, 1)}
            elif since == 3016:
                kwargs = {"ball": (2.0, 0.0), "toucher": RobotId(RED, 1)}
            elif since == 3024:
                kwargs = {"ball": (4.7, 0.0), "toucher": RobotId(RED, 1)}
                seen.add("goal")
        model.clock(match.ms)
        ours = match.step(**kwargs)  # type: ignore[arg-type]
        if before is not None:
            _command(model, before, ours)
        league = model.packet()
        for line in _differences(ours, league):
            mismatches.append(f"at {match.ms - STEP_MS} ms: {line}")
        before = ours
        # what the match went through (each must have happened)
        if ours.secondary_state == 9:
            seen.add(f"throw-in phase {ours.secondary_state_info[1]}")
        if any(p.penalty == int(Penalty.PICKUP_OR_INCAPABLE) for t in ours.teams
               for p in t.players):  # fmt: skip
            seen.add("penalised")
        elif "penalised" in seen:
            seen.add("penalty served")
        if sum(t.score for t in ours.teams) == 1:
            seen.add("scored")
        if ours.state == INITIAL and not ours.first_half:
            seen.add("half time")
            if ours.secondary_time < 0:
                seen.add("negative pause")
        if ours.state == PLAYING and not ours.first_half:
            seen.add("second half playing")
    assert not mismatches, "\n".join(mismatches[:20] + [f"({len(mismatches)} in all)"])
    assert {"throw-in phase 0", "throw-in phase 1", "throw-in phase 2", "penalised",
            "penalty served", "scored", "half time", "negative pause",
            "second half playing"} <= seen, seen  # fmt: skip
