"""orchestrator.config has one sorted public surface, pinned here."""

from __future__ import annotations

import orchestrator.config as config

EXPECTED = {
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
}


def test_public_surface_is_sorted_and_complete() -> None:
    names = list(config.__all__)
    assert names == sorted(names)
    assert set(names) == EXPECTED
    for name in names:
        assert hasattr(config, name)
