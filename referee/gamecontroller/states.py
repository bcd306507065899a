"""Values of the GameController: cards and the allowed state transitions.

The wire codes (states, secondary states, penalties...) are :mod:`contracts.gamecontroller`'s,
re-exported here for the referee's modules."""

from __future__ import annotations

from enum import StrEnum

from contracts import (
    DROPBALL_TEAM,
    GameState,
    GameTypeCode,
    Penalty,
    SecondaryState,
    TeamColourCode,
)


class Card(StrEnum):
    WARNING = "warning"
    YELLOW = "yellow"
    RED = "red"


# Which state may follow which. READY -> SET and SET -> PLAYING are the normal flow; PLAYING ->
# READY after a goal or a dropped ball; PLAYING -> FINISHED at the end of a period; FINISHED ->
# INITIAL starts the next period (time may also run out in READY or SET); in the penalty
# shoot-out every kick starts in SET, entered from INITIAL or PLAYING.
ALLOWED_TRANSITIONS: dict[GameState, frozenset[GameState]] = {
    GameState.INITIAL: frozenset({GameState.READY, GameState.SET}),
    GameState.READY: frozenset({GameState.SET, GameState.FINISHED}),
    GameState.SET: frozenset({GameState.PLAYING, GameState.FINISHED}),
    GameState.PLAYING: frozenset({GameState.READY, GameState.SET, GameState.FINISHED}),
    GameState.FINISHED: frozenset({GameState.INITIAL}),
}


__all__ = [
    "ALLOWED_TRANSITIONS",
    "DROPBALL_TEAM",
    "Card",
    "GameState",
    "GameTypeCode",
    "Penalty",
    "SecondaryState",
    "TeamColourCode",
]
