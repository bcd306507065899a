"""Dropped ball: the ball did not move (5 cm) for 120 s (configurable) of running play."""

from __future__ import annotations

from dataclasses import dataclass

from referee.rules.base import Decision, DropBall, GameView, distance2d
from referee.snapshot import Vec3, WorldSnapshot

MOVE_M = 0.05


@dataclass(frozen=True, slots=True)
class DroppedBallMemory:
    since_ms: int | None = None
    anchor: Vec3 = (0.0, 0.0, 0.0)


def judge(
    snapshot: WorldSnapshot, game: GameView, memory: DroppedBallMemory
) -> tuple[list[Decision], DroppedBallMemory]:
    if not game.running:
        return [], DroppedBallMemory()
    now = snapshot.sim_time_ms
    ball = snapshot.ball.position
    if memory.since_ms is None or distance2d(ball, memory.anchor) >= MOVE_M:
        return [], DroppedBallMemory(now, ball)
    if now - memory.since_ms >= game.timing.dropped_ball_s * 1000.0:
        reason = f"ball did not move for {game.timing.dropped_ball_s:g} s"
        return [DropBall(reason)], DroppedBallMemory()
    return [], memory
