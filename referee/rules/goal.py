"""Goals: the ball fully over the goal line, between the posts, under the bar.

A goal may not be scored directly from a kick-off, a throw-in or an indirect free kick. Such a
ball in the opponents' goal gives a goal kick, in the taker's own goal a corner kick. Own goals
count otherwise.

* After a kick-off, as the league's referee decides it (hlvs_webots
  ``controllers/referee/referee.py:2150-2168``): a goal counts once the ball was touched by a
  robot of the defending team, by a robot other than the first to touch it (the kicker), or by
  any robot after the ball had left the centre circle (its distance from the centre spot over
  the circle's radius plus the ball's, 2150-2154). A ball that merely rolls out of the circle
  and in does not score (2292-2295).
* After a throw-in or an indirect free kick: once a robot other than the taker touched it.
* An own goal after any restart (kick-off, set play, dropped ball) counts only once the ball,
  in play, was touched again, or touched by a robot other than the taker; before that it gives
  the opponents a corner kick, as the league's referee decides it (``can_score_own``, set
  False by every restart, ``referee.py:1709``, ``game.py:91, 111, 123``; True once the ball is
  in play and touched by the opponents of the team that restarts, by a robot other than the
  first to touch it, or at all after it came into play, 2159-2162, 2172-2174; an own goal
  while it is False is a corner kick, 2305-2314).

A touch is a robot's contact with the ball in a snapshot, or the world's last toucher changing
its time between two snapshots (a touch between them).
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from enum import StrEnum

from contracts import RobotId, TeamColor
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
    left_circle: bool = False  # a kick-off's ball has left the centre circle
    touch_ms: int | None = None  # the world's last touch time seen
    # an own goal counts (the league's ``can_score_own``): no restart yet, or the ball touched
    # in play since the last one
    own_cleared: bool = True
    first_toucher: RobotId | None = None  # the first robot to touch the ball since the restart
    kicking_team: TeamColor | None = None  # the team that takes the set play


def restart(
    restriction: Restriction | None,
    snapshot: WorldSnapshot | None = None,
    kicking_team: TeamColor | None = None,
) -> GoalMemory:
    """The memory of a restart; ``snapshot``, the world when it is taken, so that a touch
    before it is not counted as one after it; ``kicking_team``, the team whose set play it is
    (None: the kick-off team, or a dropped ball's)."""
    touch_ms = snapshot.last_ball_touch_ms if snapshot is not None else None
    return GoalMemory(
        restriction=restriction, touch_ms=touch_ms, own_cleared=False, kicking_team=kicking_team
    )


def _touches(snapshot: WorldSnapshot, memory: GoalMemory) -> list[RobotId]:
    touching = [r.id for r in snapshot.robots if r.ball_contacts]
    toucher = snapshot.last_ball_toucher
    touched_between = (
        snapshot.last_ball_touch_ms is not None and snapshot.last_ball_touch_ms != memory.touch_ms
    )
    if toucher is not None and touched_between and toucher not in touching:
        touching.append(toucher)
    return touching


def _update(snapshot: WorldSnapshot, game: GameView, memory: GoalMemory) -> GoalMemory:
    restricted = memory.restriction is not None and not memory.cleared
    if not restricted and memory.own_cleared:
        return memory
    touching = _touches(snapshot, memory)
    memory = replace(memory, touch_ms=snapshot.last_ball_touch_ms)
    if not memory.own_cleared:
        memory = _update_own(touching, game, memory)
    if not restricted:
        return memory
    kickoff = memory.restriction is Restriction.KICKOFF
    taker = memory.taker
    for robot in touching:
        if kickoff and (memory.left_circle or robot.team is not game.kickoff_team):
            # 2158-2161, 2164-2168: a touch after the ball left the circle, or the defenders'
            return replace(memory, taker=taker or robot, cleared=True)
        if taker is None:
            taker = robot
        elif robot != taker:
            return replace(memory, taker=taker, cleared=True)
    if kickoff and not memory.left_circle:
        radius = game.field.centre_circle_radius_m + game.field.ball_radius_m
        if distance2d(snapshot.ball.position, (0.0, 0.0)) > radius:  # 2150-2154
            return replace(memory, taker=taker, left_circle=True)
    return replace(memory, taker=taker)


def _update_own(touching: list[RobotId], game: GameView, memory: GoalMemory) -> GoalMemory:
    """The league's ``can_score_own`` (referee.py:2156-2174): a touch once the ball is in play,
    a touch by a robot other than the first to touch it since the restart (its
    ``kicking_player_number``), or by the opponents of the team that restarts
    (``ball_must_kick_team``)."""
    if not touching:
        return memory
    if game.ball_in_play:
        return replace(memory, own_cleared=True)
    first = memory.first_toucher or touching[0]
    kicking = memory.kicking_team or game.kickoff_team
    if any(r != first or (kicking is not None and r.team is not kicking) for r in touching):
        return replace(memory, first_toucher=first, own_cleared=True)
    return replace(memory, first_toucher=first)


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
    if own_goal and not memory.own_cleared:  # 2305-2314: a corner kick for the opponents
        reason = "no own goal directly from a restart"
        return [goal_line_restart(snapshot, game, goal_sign, reason)], memory
    return [Goal(defending.opponent, toucher, own_goal)], memory
