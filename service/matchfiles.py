"""The files of one test match: ``game.json`` and the two team files, in the match's folder.

The submitting team plays red with the team file version it submitted; the opponent plays blue
(the project's stub team, or the newest team file of a team that accepts friendlies). Test
matches are short, lockstep scrimmages (see :class:`service.settings.Settings`).

Both sides field the same number of robots: the service's ``test_players``
(``HLVS_SERVICE_TEST_PLAYERS``, 1 by default), the lowest-numbered players of each team file
(:func:`fielded`); when a team file has fewer, both sides field that many. A team's file with
more players is never an advantage.
"""

from __future__ import annotations

import json
from pathlib import Path

from contracts import TEST_MATCH
from orchestrator import private_dir, write_private
from orchestrator.config import TeamDocument
from orchestrator.match import ScrimmageRequest, game_file, team_file
from service.settings import Settings

OWN_COLOR = "red"
"""The submitting team plays red in its test matches (and sees only red's logs)."""


def _ports(base: int, team: TeamDocument) -> list[int]:
    players = team.get("players") or {}
    return [base + n for n in range(1, max(1, len(players)) + 1)]


def player_count(team: TeamDocument) -> int:
    return len(team.get("players") or {})


def fielded(team: TeamDocument, count: int) -> TeamDocument:
    """``team`` with its ``count`` lowest-numbered players only."""
    players = team.get("players") or {}
    kept = sorted(players, key=lambda number: (not number.isdigit(),
                                               int(number) if number.isdigit() else 0,
                                               number))[:count]
    return {**team, "players": {number: players[number] for number in kept}}


def write_match(folder: Path, *, match_id: str, team: TeamDocument,
                opponent: TeamDocument | None, stub_image: str | None,
                settings: Settings, seed: int) -> Path:
    """Write the match files into ``folder``; returns the game.json path."""
    if opponent is None:
        assert stub_image is not None
        opponent = team_file("Stub", stub_image, settings.test_players, goalie_first=True)
    count = min(settings.test_players, player_count(team), player_count(opponent))
    team, opponent = fielded(team, count), fielded(opponent, count)
    request = ScrimmageRequest(players=settings.test_players, seed=seed,
                               half_duration_s=settings.test_half_duration_s,
                               ready_duration_s=settings.test_ready_duration_s,
                               wait_before_ready_s=TEST_MATCH.wait_before_first_ready_s,
                               grace_s=settings.test_grace_s)
    game = game_file(request, match_id)
    game["registry_images"] = True  # a team's images only from its registry, with its login
    game["red"]["ports"] = _ports(10000, team)
    game["blue"]["ports"] = _ports(10020, opponent)
    private_dir(folder)  # the team files hold registry logins
    files = {"game.json": game, "team_red.json": team, "team_blue.json": opponent}
    for name, content in files.items():
        write_private(folder / name, json.dumps(content, indent=2) + "\n")
    return folder / "game.json"


__all__ = ["OWN_COLOR", "fielded", "player_count", "write_match"]
