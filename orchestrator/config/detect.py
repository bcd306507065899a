"""Telling which kind of configuration file a document is, from its keys."""

from __future__ import annotations

from pathlib import Path
from typing import Any, Literal

Kind = Literal["game", "team", "credentials", "schedule"]
KINDS: tuple[Kind, ...] = ("game", "team", "credentials", "schedule")

_GAME_KEYS = {"red", "blue", "class", "maximum_real_time_factor", "minimum_real_time_factor"}
_TEAM_KEYS = {"players"}
_CREDENTIALS_KEYS = {"credentials"}
_SCHEDULE_KEYS = {"matches", "teams", "round_robin", "simulator_slots"}
YAML_SUFFIXES = (".yaml", ".yml")


def kind_by_name(path: Path) -> Kind | None:
    """The kind a file name alone tells (schedules are YAML), else None."""
    return "schedule" if path.suffix.lower() in YAML_SUFFIXES else None


def kind_by_content(document: Any) -> Kind | None:
    """The kind of a parsed JSON document by its top-level keys, None when it is unclear."""
    if not isinstance(document, dict):
        return None
    keys = set(document)
    if keys & _TEAM_KEYS and not keys & _GAME_KEYS:
        return "team"
    if keys & _GAME_KEYS:
        return "game"
    if keys & _CREDENTIALS_KEYS or document.get("type") in ("sftp", "s3"):
        return "credentials"
    if keys & _SCHEDULE_KEYS:
        return "schedule"
    if document.get("type") in ("NORMAL", "KNOCKOUT", "PENALTY"):
        return "game"
    if "name" in keys:
        return "team"
    return None
