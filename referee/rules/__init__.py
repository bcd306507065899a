"""AutoRef rules, one module per rule of the book, each a pure function of
(snapshot, game view, rule memory) returning decisions and the next memory."""

from __future__ import annotations

from referee.rules.base import (
    AwardSetPlay,
    BallInPlay,
    Decision,
    DropBall,
    GameView,
    GiveCard,
    Goal,
    PenalizeRobot,
)

__all__ = [
    "AwardSetPlay",
    "BallInPlay",
    "Decision",
    "DropBall",
    "GameView",
    "GiveCard",
    "Goal",
    "PenalizeRobot",
]
