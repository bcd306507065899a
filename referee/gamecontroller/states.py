"""Values of the GameController: states, secondary states, penalties, cards (wire codes)."""

from __future__ import annotations

from enum import IntEnum, StrEnum


class GameState(IntEnum):
    INITIAL = 0
    READY = 1
    SET = 2
    PLAYING = 3
    FINISHED = 4


class SecondaryState(IntEnum):
    NORMAL = 0
    PENALTYSHOOT = 1
    OVERTIME = 2
    TIMEOUT = 3
    DIRECT_FREEKICK = 4
    INDIRECT_FREEKICK = 5
    PENALTYKICK = 6
    CORNER_KICK = 7
    GOAL_KICK = 8
    THROW_IN = 9

    @property
    def is_set_play(self) -> bool:
        return self.value >= SecondaryState.DIRECT_FREEKICK.value


class Penalty(IntEnum):
    """Penalty codes on the wire (GameController ``Penalties.java``)."""

    NONE = 0
    SUBSTITUTE = 14
    MANUAL = 15
    BALL_MANIPULATION = 30
    PHYSICAL_CONTACT = 31
    ILLEGAL_ATTACK = 32
    ILLEGAL_DEFENSE = 33
    PICKUP_OR_INCAPABLE = 34
    SERVICE = 35


class Card(StrEnum):
    WARNING = "warning"
    YELLOW = "yellow"
    RED = "red"


class GameTypeCode(IntEnum):
    ROUNDROBIN = 0
    PLAYOFF = 1
    DROPIN = 2


class TeamColourCode(IntEnum):
    BLUE = 0
    RED = 1


DROPBALL_TEAM = 128  # kickOffTeam after a dropped ball

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
