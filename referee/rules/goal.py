"""Goals: the ball fully over the goal line, between the posts, under the bar.

A goal may not be scored directly from a kick-off (until the ball left the centre circle or was
touched by a player other than the kicker), a throw-in or an indirect free kick (until a player
other than the taker touched it). Such a ball in the opponents' goal gives a goal kick, in the
taker's own goal a corner kick. Own goals count otherwise.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from enum import StrEnum

from contracts import RobotId
from referee.rules.ball_out import goal_line_restart, in_goal
from referee.rules.base import Decision, GameView, Goal, distance2d
from referee.snapshot import WorldSnapshot


class Restriction(StrEnum):
    KICKOFF = "kick-off"
    THROW_IN = "throw-in"
    INDIRECT_FREE_KICK = "indirect free kick"


@dataclass(frozen=True, slots=True)
class GoalMemory:
    restriction: Restriction | None = None
    taker: RobotId | None = None  # first robot to touch the ball after the restart
    cleared: bool = False  # the restriction no longer applies


def restart(restriction: Restriction | None) -> GoalMemory:
    return GoalMemory(restriction=restriction)


def _update(snapshot: WorldSnapshot, game: GameView, memory: GoalMemory) -> GoalMemory:
    if memory.restriction is None or memory.cleared:
        return memory
    touching = [r.id for r in snapshot.robots if r.ball_contacts]
    taker = memory.taker
    for robot in touching:
        if taker is None:
            taker = robot
        elif robot != taker:
            return replace(memory, taker=taker, cleared=True)
    if memory.restriction is Restriction.KICKOFF:
        radius = game.field.centre_circle_radius_m + game.field.ball_radius_m
        if distance2d(snapshot.ball.position, (0.0, 0.0)) > radius:
            return replace(memory, taker=taker, cleared=True)
    return replace(memory, taker=taker)


def judge(
    snapshot: WorldSnapshot, game: GameView, memory: GoalMemory
) -> tuple[list[Decision], GoalMemory]:
    before, memory = memory, _update(snapshot, game, memory)
    if not game.running or not in_goal(snapshot.ball.position, game.field):
        return [], memory
    memory = before  # the restriction as it stood while the ball was still on the field
    goal_sign = -1.0 if snapshot.ball.position[0] < 0 else 1.0
    defending = game.team_on_side(goal_sign)
    toucher = snapshot.last_ball_toucher
    if memory.restriction is not None and not memory.cleared:
        reason = f"no goal directly from a {memory.restriction.value}"
        return [goal_line_restart(snapshot, game, goal_sign, reason)], memory
    own_goal = toucher is not None and toucher.team is defending
    return [Goal(defending.opponent, toucher, own_goal)], memory
