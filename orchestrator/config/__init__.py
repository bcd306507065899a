"""Configuration layer: the only code that reads game.json and team_config.json.

``load_game(path)`` validates game.json and the team files it references (JSON Schema, then the
cross-file rules) and returns frozen dataclasses; every problem found is raised at once in one
:class:`orchestrator.errors.ConfigError`.
"""

from __future__ import annotations

from orchestrator.config.model import (
    COLORS,
    DEFAULT_MODEL,
    MAX_PLAYERS,
    Color,
    EcrAuth,
    FieldClass,
    GameConfig,
    GameType,
    Limits,
    LoadedGame,
    LoadedTeam,
    PlayerConfig,
    RegistryAuth,
    SideChoice,
    StartingPose,
    SteppingMode,
    TeamConfig,
    TeamRef,
    Timing,
)

__all__ = [
    "COLORS",
    "Color",
    "DEFAULT_MODEL",
    "EcrAuth",
    "FieldClass",
    "GameConfig",
    "GameType",
    "Limits",
    "LoadedGame",
    "LoadedTeam",
    "MAX_PLAYERS",
    "PlayerConfig",
    "RegistryAuth",
    "SideChoice",
    "StartingPose",
    "SteppingMode",
    "TeamConfig",
    "TeamRef",
    "Timing",
]
