"""orchestrator.config has one sorted public surface, pinned here."""

from __future__ import annotations

import orchestrator.config as config

EXPECTED = {
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
}


def test_public_surface_is_sorted_and_complete() -> None:
    names = list(config.__all__)
    assert names == sorted(names)
    assert set(names) == EXPECTED
    for name in names:
        assert hasattr(config, name)
