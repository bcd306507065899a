"""Ball holding: a team holds the ball when a circle of radius r/3 around the ball centre
intersects the XY convex hull of the hand and foot points of all its robots within the ball
vicinity. Holding for more than half of a 5 s sliding window gives the opponents a direct free
kick at the ball position (no removal)."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from contracts import TeamColor
from referee.gamecontroller.states import SecondaryState
from referee.rules.base import Decision, GameView, distance2d, free_kick
from referee.snapshot import Vec2, WorldSnapshot

WINDOW_S = 5.0
RADIUS_RATIO = 1.0 / 3.0

Interval = tuple[int, int]  # [start_ms, end_ms) of holding


@dataclass(frozen=True, slots=True)
class BallHoldingMemory:
    holding: dict[TeamColor, tuple[Interval, ...]] = field(default_factory=dict)
    last_ms: int | None = None


def convex_hull(points: list[Vec2]) -> list[Vec2]:
    """Andrew's monotone chain; counter-clockwise, without repeated points."""
    pts = sorted(set(points))
    if len(pts) <= 2:
        return pts

    def cross(o: Vec2, a: Vec2, b: Vec2) -> float:
        return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])

    lower: list[Vec2] = []
    for p in pts:
        while len(lower) >= 2 and cross(lower[-2], lower[-1], p) <= 0:
            lower.pop()
        lower.append(p)
    upper: list[Vec2] = []
    for p in reversed(pts):
        while len(upper) >= 2 and cross(upper[-2], upper[-1], p) <= 0:
            upper.pop()
        upper.append(p)
    return lower[:-1] + upper[:-1]


def _segment_distance(p: np.ndarray, a: np.ndarray, b: np.ndarray) -> float:
    ab = b - a
    length2 = float(ab @ ab)
    t = 0.0 if length2 == 0.0 else max(0.0, min(1.0, float((p - a) @ ab) / length2))
    return float(np.linalg.norm(p - (a + t * ab)))


def circle_meets_hull(centre: Vec2, radius: float, hull: list[Vec2]) -> bool:
    if not hull:
        return False
    p = np.asarray(centre, dtype=float)
    vertices = np.asarray(hull, dtype=float)
    if len(hull) >= 3:
        edges = np.roll(vertices, -1, axis=0) - vertices
        rel = p - vertices
        if np.all(edges[:, 0] * rel[:, 1] - edges[:, 1] * rel[:, 0] >= 0):
            return True  # centre inside the counter-clockwise polygon
    count = len(hull)
    return any(
        _segment_distance(p, vertices[i], vertices[(i + 1) % count]) <= radius
        for i in range(count if count > 1 else 1)
    )


def team_holds(snapshot: WorldSnapshot, game: GameView, team: TeamColor) -> bool:
    ball = snapshot.ball.position
    points: list[Vec2] = []
    for robot in snapshot.robots:
        if robot.id.team is team and game.active(robot):
            if distance2d(robot.position, ball) < game.field.ball_vicinity_m:
                points.extend(robot.hull_points)
    radius = game.field.ball_radius_m * RADIUS_RATIO
    return circle_meets_hull((ball[0], ball[1]), radius, convex_hull(points))


def judge(
    snapshot: WorldSnapshot, game: GameView, memory: BallHoldingMemory
) -> tuple[list[Decision], BallHoldingMemory]:
    if not game.running or game.phase is SecondaryState.PENALTYSHOOT:
        return [], BallHoldingMemory()
    now = snapshot.sim_time_ms
    previous = memory.last_ms if memory.last_ms is not None else now
    window_start = now - int(WINDOW_S * 1000)
    decisions: list[Decision] = []
    holding: dict[TeamColor, tuple[Interval, ...]] = {}
    for team in (TeamColor.RED, TeamColor.BLUE):
        intervals = [iv for iv in memory.holding.get(team, ()) if iv[1] > window_start]
        if team_holds(snapshot, game, team):
            if intervals and intervals[-1][1] == previous:
                intervals[-1] = (intervals[-1][0], now)
            else:
                intervals.append((previous, now))
        held_ms = sum(end - max(start, window_start) for start, end in intervals)
        if held_ms > WINDOW_S * 1000 / 2:
            ball = snapshot.ball.position
            decisions.append(
                free_kick(team.opponent, (ball[0], ball[1]), ball, game,
                          f"ball holding by the {team.value} team")
            )  # fmt: skip
            intervals = []
        holding[team] = tuple(intervals)
    return decisions, BallHoldingMemory(holding, now)
