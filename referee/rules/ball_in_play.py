"""The ball is in play after a kick-off or a set play once it moved 5 cm or 10 s passed.

The 5 cm are measured along the ground, as the league's referee measures them (hlvs_webots
``controllers/referee/referee.py:2140-2142``: ``distance2``, ``geometry.py:20-21``, the
distance in x and y; ``BALL_IN_PLAY_MOVE: 0.05``, ``referee_config.yaml:22``): a ball lifted
where it lies, as off a robot's knee, has not moved."""

from __future__ import annotations

from dataclasses import dataclass

from referee.rules.base import BallInPlay, Decision, GameView
from referee.snapshot import Vec3, WorldSnapshot

MOVE_M = 0.05


@dataclass(frozen=True, slots=True)
class BallInPlayMemory:
    start_ms: int | None = None  # None: not armed (ball in play or game stopped)
    origin: Vec3 = (0.0, 0.0, 0.0)


def arm(snapshot: WorldSnapshot) -> BallInPlayMemory:
    return BallInPlayMemory(start_ms=snapshot.sim_time_ms, origin=snapshot.ball.position)


def judge(
    snapshot: WorldSnapshot, game: GameView, memory: BallInPlayMemory
) -> tuple[list[Decision], BallInPlayMemory]:
    if memory.start_ms is None or game.ball_in_play or game.set_play is not None:
        return [], memory
    x, y, _ = snapshot.ball.position
    ox, oy, _ = memory.origin
    if ((x - ox) ** 2 + (y - oy) ** 2) ** 0.5 >= MOVE_M:
        return [BallInPlay("ball moved")], BallInPlayMemory()
    if snapshot.sim_time_ms - memory.start_ms >= game.timing.kickoff_blocked_s * 1000.0:
        return [BallInPlay(f"{game.timing.kickoff_blocked_s:g} s elapsed")], BallInPlayMemory()
    return [], memory
