"""What every rule sees (:class:`GameView`) and what it may decide (:data:`Decision`).

A rule is a pure function ``judge(snapshot, game, memory) -> (decisions, memory)``: it reads one
:class:`~referee.snapshot.WorldSnapshot`, the game state and its own frozen memory, and returns
its decisions and its next memory. The referee applies the decisions in rule order.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping
from dataclasses import dataclass

from contracts import FieldGeometry, RobotId, TeamColor
from referee.config import TimingConfig
from referee.gamecontroller.machine import SetPlay
from referee.gamecontroller.states import Card, GameState, Penalty, SecondaryState
from referee.snapshot import RobotState, Vec2, Vec3, WorldSnapshot


@dataclass(frozen=True, slots=True, kw_only=True)
class GameView:
    state: GameState
    phase: SecondaryState  # NORMAL, OVERTIME or PENALTYSHOOT
    set_play: SetPlay | None
    half: int
    kickoff_team: TeamColor | None  # None: dropped ball
    left_team: TeamColor  # the team defending the goal at x < 0 now
    ball_in_play: bool
    penalised: frozenset[RobotId]
    goalkeepers: frozenset[RobotId]
    field: FieldGeometry
    timing: TimingConfig

    def side_sign(self, team: TeamColor) -> float:
        """-1 for the team defending x < 0, +1 for the other."""
        return -1.0 if team is self.left_team else 1.0

    def team_on_side(self, sign: float) -> TeamColor:
        return self.left_team if sign < 0 else self.left_team.opponent

    @property
    def running(self) -> bool:
        """The game runs normally: PLAYING, no set play, not a shoot-out."""
        return (
            self.state is GameState.PLAYING
            and self.set_play is None
            and self.phase is not SecondaryState.PENALTYSHOOT
        )

    def active(self, robot: RobotState) -> bool:
        return not robot.removed and not robot.limp and robot.id not in self.penalised


@dataclass(frozen=True, slots=True)
class Goal:
    scoring: TeamColor
    scorer: RobotId | None
    own_goal: bool


@dataclass(frozen=True, slots=True)
class AwardSetPlay:
    kind: SecondaryState
    team: TeamColor
    position: Vec2
    reason: str


@dataclass(frozen=True, slots=True)
class PenalizeRobot:
    robot: RobotId
    penalty: Penalty
    reason: str


@dataclass(frozen=True, slots=True)
class GiveCard:
    robot: RobotId
    card: Card
    reason: str


@dataclass(frozen=True, slots=True)
class DropBall:
    reason: str


@dataclass(frozen=True, slots=True)
class BallInPlay:
    reason: str


@dataclass(frozen=True, slots=True)
class RetakeSetPlay:
    """An opponent of the set-play team touched the ball before the set play was taken: it
    starts again from sub-phase 0, the ball placed again (the GameController's RETAKE)."""

    robot: RobotId
    reason: str


@dataclass(frozen=True, slots=True)
class AbortSetPlay:
    """The set-play team touched the ball before the set play was taken: it is cancelled and
    the ball is in play (the GameController's ABORT)."""

    robot: RobotId
    reason: str


Decision = (
    Goal | AwardSetPlay | PenalizeRobot | GiveCard | DropBall | BallInPlay | RetakeSetPlay
    | AbortSetPlay
)


def distance2d(a: Vec2 | Vec3, b: Vec2 | Vec3) -> float:
    return math.hypot(a[0] - b[0], a[1] - b[1])


def free_kick(
    team: TeamColor, spot: Vec2, ball: Vec2 | Vec3, game: GameView, reason: str
) -> AwardSetPlay:
    """A direct free kick for ``team`` at ``spot``, or a penalty kick (on the penalty mark)
    when the ball lies fully inside the penalty area ``team`` attacks, as the league's referee
    decides a free kick (hlvs_webots referee.py:1682-1704 with field.py:55-58)."""
    f = game.field
    r = f.ball_radius_m
    attacked = -game.side_sign(team)  # the sign of x of the goal team attacks
    x, y = ball[0] * attacked, ball[1]
    inside = (
        x - r > f.half_length_m - f.penalty_area_length_m
        and x + r < f.half_length_m
        and abs(y) + r < f.penalty_area_width_m / 2.0
    )
    if inside:
        mark = (attacked * f.penalty_mark_x_m, 0.0)
        return AwardSetPlay(SecondaryState.PENALTYKICK, team, mark, reason)
    return AwardSetPlay(SecondaryState.DIRECT_FREEKICK, team, spot, reason)


def timers(
    active: Iterable[RobotId], since: Mapping[RobotId, int], now_ms: int, limit_s: float
) -> tuple[list[RobotId], dict[RobotId, int]]:
    """Per-robot condition timers: returns the robots whose condition held longer than
    ``limit_s`` (their timer is dropped) and the new start times of the others."""
    expired: list[RobotId] = []
    kept: dict[RobotId, int] = {}
    for robot in active:
        start = since.get(robot, now_ms)
        if now_ms - start > limit_s * 1000.0:
            expired.append(robot)
        else:
            kept[robot] = start
    return expired, kept


def ball_speed(snapshot: WorldSnapshot) -> float:
    vx, vy, vz = snapshot.ball.velocity
    return math.sqrt(vx * vx + vy * vy + vz * vz)
