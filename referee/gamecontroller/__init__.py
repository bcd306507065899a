"""The GameController: state machine on simulated time and its wire values."""

from __future__ import annotations

from referee.gamecontroller.machine import GameController, RobotStatus, SetPlay, TeamStatus, Tick
from referee.gamecontroller.packet import LEAGUE_PLAYERS_PER_TEAM, game_control_data
from referee.gamecontroller.states import (
    DROPBALL_TEAM,
    Card,
    GameState,
    Penalty,
    SecondaryState,
)

__all__ = [
    "DROPBALL_TEAM",
    "LEAGUE_PLAYERS_PER_TEAM",
    "Card",
    "GameController",
    "GameState",
    "Penalty",
    "RobotStatus",
    "SecondaryState",
    "SetPlay",
    "TeamStatus",
    "Tick",
    "game_control_data",
]
