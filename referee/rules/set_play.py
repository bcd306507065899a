"""Set-play compliance.

- When a set play is executed, opponents of the executing team closer to the ball than the
  opponent distance (0.75 m kid, 1.5 m adult) are removed (INCAPABLE).
- A touch of the ball in sub-phases 1 and 2, before the set play is taken, as the league's
  referee judges it (touching it in sub-phase 0 is allowed): by an opponent of the set-play team,
  the set play is retaken (RETAKE); by the set-play team, it is aborted and the ball is in play
  (ABORT). The robot that touched it gets a warning either way.
"""

from __future__ import annotations

from referee.gamecontroller.machine import SetPlay
from referee.gamecontroller.states import Card, GameState, Penalty
from referee.rules.base import (
    AbortSetPlay,
    Decision,
    GameView,
    GiveCard,
    PenalizeRobot,
    RetakeSetPlay,
    distance2d,
)
from referee.snapshot import WorldSnapshot


def judge_execute(snapshot: WorldSnapshot, game: GameView, play: SetPlay) -> list[Decision]:
    limit = game.field.opponent_distance_m
    reason = f"closer than {limit:g} m to the ball at the {play.kind.name.lower()}"
    return [
        PenalizeRobot(robot.id, Penalty.PICKUP_OR_INCAPABLE, reason)
        for robot in snapshot.robots
        if robot.id.team is not play.team
        and game.active(robot)
        and distance2d(robot.position, snapshot.ball.position) < limit
    ]


def judge_touch(snapshot: WorldSnapshot, game: GameView) -> list[Decision]:
    """The first robot that touches the ball in sub-phase 1 or 2 of a set play: RETAKE or
    ABORT, and a warning for it."""
    play = game.set_play
    if play is None or play.sub_phase == 0 or game.state is not GameState.PLAYING:
        return []
    name = play.kind.name.lower().replace("_", " ")
    for robot in snapshot.robots:
        if not robot.ball_contacts or not game.active(robot):
            continue
        if robot.id.team is play.team:
            reason = f"touched the ball before its team's {name} was taken"
            return [AbortSetPlay(robot.id, reason), GiveCard(robot.id, Card.WARNING, reason)]
        reason = f"touched the ball at the opponents' {name}"
        return [RetakeSetPlay(robot.id, reason), GiveCard(robot.id, Card.WARNING, reason)]
    return []
