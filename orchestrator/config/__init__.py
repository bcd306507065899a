"""Configuration layer: the only code that reads game.json and team_config.json.

``parse_game(document, source=...)`` validates a game.json document and its teams (JSON Schema,
then the cross-file rules) and returns frozen dataclasses; ``parse_team`` one team document.
Every problem found is raised at once in one :class:`orchestrator.errors.ConfigError`. Files are
one way to get a document: ``load_game(path)`` and ``load_team(path)`` read one and parse it.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from contracts import lazy_exports
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

if TYPE_CHECKING:
    from orchestrator.config.credentials import parse_credentials
    from orchestrator.config.detect import Kind, kind_by_content, kind_by_name
    from orchestrator.config.jsonfile import parse_json, read_text
    from orchestrator.config.robot_models import (
        BUILT_IN_MODELS,
        check_model,
        describe,
        is_model_package,
        model_devices,
    )
    from orchestrator.config.schedule import (
        PlannedMatch,
        Schedule,
        ScheduledTeam,
        SchedulePool,
        Slot,
        game_document,
        load_schedule,
        resolve_time,
    )
    from orchestrator.config.schedule_check import check_schedule

__all__ = [
    "BUILT_IN_MODELS",
    "COLORS",
    "Color",
    "DEFAULT_MODEL",
    "EcrAuth",
    "FieldClass",
    "GameConfig",
    "GameDocument",
    "GameType",
    "Kind",
    "Limits",
    "LoadedGame",
    "LoadedTeam",
    "MAX_PLAYERS",
    "PlannedMatch",
    "PlayerConfig",
    "PlayerDocument",
    "PoseDocument",
    "RegistryAuth",
    "Schedule",
    "SchedulePool",
    "ScheduledTeam",
    "SideChoice",
    "Slot",
    "StartingPose",
    "SteppingMode",
    "TeamConfig",
    "TeamDocument",
    "TeamRef",
    "Timing",
    "check_game",
    "check_model",
    "check_schedule",
    "check_team",
    "check_team_document",
    "default_match_id",
    "default_seed",
    "describe",
    "game_document",
    "is_model_package",
    "kind_by_content",
    "kind_by_name",
    "load_game",
    "load_schedule",
    "load_team",
    "model_devices",
    "parse_credentials",
    "parse_game",
    "parse_json",
    "parse_team",
    "read_text",
    "resolve_sides",
    "resolve_time",
    "to_match_spec",
]


if not TYPE_CHECKING:
    __getattr__, __dir__ = lazy_exports(__name__, {
        "orchestrator.config.credentials": ("parse_credentials",),
        "orchestrator.config.detect": ("Kind", "kind_by_content", "kind_by_name"),
        "orchestrator.config.jsonfile": ("parse_json", "read_text"),
        "orchestrator.config.robot_models": (
            "BUILT_IN_MODELS", "check_model", "describe", "is_model_package", "model_devices",
        ),
        "orchestrator.config.schedule": (
            "PlannedMatch", "Schedule", "SchedulePool", "ScheduledTeam", "Slot", "game_document",
            "load_schedule", "resolve_time",
        ),
        "orchestrator.config.schedule_check": ("check_schedule",),
    })
