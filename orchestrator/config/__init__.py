"""Configuration layer: the only code that reads game.json and team_config.json.

``parse_game(document, source=...)`` validates a game.json document and its teams (JSON Schema,
then the cross-file rules) and returns frozen dataclasses; ``parse_team`` one team document.
Every problem found is raised at once in one :class:`orchestrator.errors.ConfigError`. Files are
one way to get a document: ``load_game(path)`` and ``load_team(path)`` read one and parse it.
"""

from __future__ import annotations

from orchestrator.config.documents import GameDocument, PlayerDocument, PoseDocument, TeamDocument
from orchestrator.config.game import default_match_id, default_seed
from orchestrator.config.loader import (
    check_game,
    check_team,
    check_team_document,
    load_game,
    load_team,
    parse_game,
    parse_team,
)
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
from orchestrator.config.spec import resolve_sides, to_match_spec

__all__ = [
    "COLORS",
    "Color",
    "DEFAULT_MODEL",
    "EcrAuth",
    "FieldClass",
    "GameConfig",
    "GameDocument",
    "GameType",
    "Limits",
    "LoadedGame",
    "LoadedTeam",
    "MAX_PLAYERS",
    "PlayerConfig",
    "PlayerDocument",
    "PoseDocument",
    "RegistryAuth",
    "SideChoice",
    "StartingPose",
    "SteppingMode",
    "TeamConfig",
    "TeamDocument",
    "TeamRef",
    "Timing",
    "check_game",
    "check_team",
    "check_team_document",
    "default_match_id",
    "default_seed",
    "load_game",
    "load_team",
    "parse_game",
    "parse_team",
    "resolve_sides",
    "to_match_spec",
]
