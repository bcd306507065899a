"""The rules in the order the referee applies them, with their memories.

Order: ball in play, goal (else ball out), touches before a set play is taken, opponents near
the ball after a set play was taken, kick-off,
fallen, outside turf, ball holding, pushing, inactive goalkeeper, dropped ball. (Kick-off
positions are judged by the referee through SET, set-play compliance at EXECUTE once, when the
GameController enters it.) Each rule is a pure function; this class only keeps each rule's memory
from one step to the next.
"""

from __future__ import annotations

from contracts import TeamColor
from referee.rules import (
    ball_holding,
    ball_in_play,
    ball_out,
    dropped_ball,
    fallen,
    goal,
    goalkeeper,
    kickoff,
    outside_turf,
    pushing,
    set_play,
)
from referee.rules.base import Decision, GameView
from referee.snapshot import WorldSnapshot


class RuleBook:
    def __init__(self) -> None:
        self.goal = goal.GoalMemory()
        self.in_play = ball_in_play.BallInPlayMemory()
        self.fallen = fallen.FallenMemory()
        self.turf = outside_turf.OutsideTurfMemory()
        self.holding = ball_holding.BallHoldingMemory()
        self.pushing = pushing.PushingMemory()
        self.keeper = goalkeeper.GoalkeeperMemory()
        self.dropped = dropped_ball.DroppedBallMemory()
        self.after_kickoff = False  # the last restart was a kick-off
        self.set_play_team: TeamColor | None = None  # whose set play was taken last

    def restart(
        self,
        snapshot: WorldSnapshot,
        restriction: goal.Restriction | None,
        set_play_team: TeamColor | None = None,
    ) -> None:
        """The ball is about to be in play again (kick-off, or ``set_play_team``'s set play
        executed)."""
        self.in_play = ball_in_play.arm(snapshot)
        self.goal = goal.restart(restriction, snapshot, set_play_team)
        # the kick-off's own rules (the defenders keep off the ball and out of the circle
        # until it is in play) hold after a kick-off only, not after a set play (hlvs_webots
        # referee.py:2136-2138: `self.game.phase == 'KICKOFF'`)
        self.after_kickoff = restriction is goal.Restriction.KICKOFF
        self.set_play_team = set_play_team

    def judge(self, snapshot: WorldSnapshot, view: GameView) -> list[Decision]:
        decisions: list[Decision] = []
        found, self.in_play = ball_in_play.judge(snapshot, view, self.in_play)
        decisions += found
        found, self.goal = goal.judge(snapshot, view, self.goal)
        decisions += found or ball_out.judge(snapshot, view)
        decisions += set_play.judge_touch(snapshot, view)
        decisions += set_play.judge_before_in_play(snapshot, view, self.set_play_team)
        if self.after_kickoff:
            decisions += kickoff.judge_before_in_play(snapshot, view)
        found, self.fallen = fallen.judge(snapshot, view, self.fallen)
        decisions += found
        found, self.turf = outside_turf.judge(snapshot, view, self.turf)
        decisions += found
        found, self.holding = ball_holding.judge(snapshot, view, self.holding)
        decisions += found
        found, self.pushing = pushing.judge(snapshot, view, self.pushing)
        decisions += found
        found, self.keeper = goalkeeper.judge(snapshot, view, self.keeper)
        decisions += found
        found, self.dropped = dropped_ball.judge(snapshot, view, self.dropped)
        decisions += found
        return decisions
