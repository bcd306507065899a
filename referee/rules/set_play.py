"""Set-play compliance.

- When a set play is executed, opponents of the executing team closer to the ball than the
  opponent distance (0.75 m kid, 1.5 m adult) are removed (INCAPABLE).
- At a penalty kick's EXECUTE, robots beyond the penalty mark (but the defending goalkeeper on
  its goal line), defenders near the ball and a second attacker near it are removed too.
- After a set play was taken, until the ball is in play, opponents of the set-play team nearer
  to the ball than that distance are removed (INCAPABLE).
- A touch of the ball in sub-phases 1 and 2, before the set play is taken, as the league's
  referee judges it (touching it in sub-phase 0 is allowed): by an opponent of the set-play team,
  the set play is retaken (RETAKE); by the set-play team, it is aborted and the ball is in play
  (ABORT). The robot that touched it gets a warning either way.
"""

from __future__ import annotations

from contracts import TeamColor
from referee.gamecontroller.machine import SetPlay
from referee.gamecontroller.states import Card, GameState, Penalty, SecondaryState
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

GOAL_LINE_TOLERANCE_M = 0.1  # a goalkeeper's torso this near the goal line stands on it


def judge_execute(snapshot: WorldSnapshot, game: GameView, play: SetPlay) -> list[Decision]:
    limit = game.field.opponent_distance_m
    reason = f"closer than {limit:g} m to the ball at the {play.kind.name.lower()}"
    decisions: list[Decision] = [
        PenalizeRobot(robot.id, Penalty.PICKUP_OR_INCAPABLE, reason)
        for robot in snapshot.robots
        if robot.id.team is not play.team
        and game.active(robot)
        and distance2d(robot.position, snapshot.ball.position) < limit
    ]
    if play.kind is SecondaryState.PENALTYKICK:
        decisions += judge_penalty_kick_positions(snapshot, game, play)
    return decisions


def judge_penalty_kick_positions(
    snapshot: WorldSnapshot, game: GameView, play: SetPlay
) -> list[Decision]:
    """A penalty kick's EXECUTE, as the league's referee checks it (hlvs_webots referee.py:
    395-396 calling ``check_penalty_kick_positions``, 1180-1209), robots of the red team first,
    each team by number: a robot beyond the penalty mark (farther from the centre than the mark,
    in the ball's half) is removed unless it is the defending goalkeeper on its goal line or
    behind it (its torso within :data:`GOAL_LINE_TOLERANCE_M` of the line's outer edge, within
    the goal's width of the centre: the league reads the feet's contact with the line and its
    ``GOAL_WIDTH``); a robot nearer to the ball than the set-play distance is removed if it
    defends, or if a team-mate nearer in that order is already the striker. INCAPABLE."""
    field = game.field
    ball_x = snapshot.ball.position[0]
    decisions: list[Decision] = []
    order = sorted(snapshot.robots, key=lambda r: (r.id.team.value != "red", r.id.number))
    striker: dict[TeamColor, bool] = {}
    for robot in order:
        if not game.active(robot):
            continue
        team = robot.id.team
        defending = team is not play.team
        x, y = robot.position[0], robot.position[1]
        ahead = ball_x * x > 0 and abs(x) > field.penalty_mark_x_m
        near = distance2d(snapshot.ball.position, robot.position) < field.opponent_distance_m
        reason: str | None = None
        if ahead:
            if not defending:
                reason = "field player of the attacking team in front of the penalty mark"
            elif robot.id in game.goalkeepers:
                on_line = abs(x) >= field.half_length_m - GOAL_LINE_TOLERANCE_M
                if not (on_line and abs(y) <= field.goal_width_m):
                    reason = "defending goalkeeper between the goal line and the penalty mark"
            else:
                reason = "field player of the defending team in front of the penalty mark"
        elif near:
            if defending:
                reason = "player of the defending team near the ball at the penalty kick"
            elif striker.get(team):
                reason = "player of the attacking team near the ball: it has a striker already"
            else:
                striker[team] = True
        if reason is not None:
            decisions.append(PenalizeRobot(robot.id, Penalty.PICKUP_OR_INCAPABLE, reason))
    return decisions


def judge_before_in_play(
    snapshot: WorldSnapshot, game: GameView, team: TeamColor | None
) -> list[Decision]:
    """After ``team``'s set play was taken, until the ball is in play: an opponent nearer to the
    ball than the set-play distance is removed (INCAPABLE), as the league's referee checks it
    every step (hlvs_webots referee.py:2131-2135, ``check_team_away_from_ball``)."""
    if team is None or not game.running or game.ball_in_play:
        return []
    limit = game.field.opponent_distance_m
    reason = f"closer than {limit:g} m to the ball before it was in play after a set play"
    return [
        PenalizeRobot(robot.id, Penalty.PICKUP_OR_INCAPABLE, reason)
        for robot in snapshot.robots
        if robot.id.team is not team
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
