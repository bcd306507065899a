"""goalKeeperStartingPose is the goalkeeper's only: the league's referee (``referee.py``) uses it
for the robot the GameController marks as goalkeeper, in a penalty shoot-out, and refuses no
team file for it. One rule (:func:`orchestrator.config.team.check_goalkeeper_pose`) for the
upload (no field class), ``hlvs check`` and the match / pre-flight (with the class)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest

from orchestrator.config import FieldClass, check_game, check_team, load_game
from tests.unit.config.conftest import GameFiles

KEEPER = "goalKeeperStartingPose"


def _bitbots_like(team: dict[str, Any]) -> None:
    """As the league's ``teams/bitbots.json``: players 2 to 4 give their own starting spot."""
    for number, (x, y) in {"2": (-1.6, 3.2), "3": (-1.6, -3.2), "4": (-1.6, 3.2)}.items():
        team["players"][number][KEEPER]["translation"] = [x, y, 0.43]


def _problems_at(problems: list[Any], fragment: str) -> list[Any]:
    return [p for p in problems if fragment in p.pointer]


def test_a_field_players_goalkeeper_pose_is_no_error_in_any_check(
    game_files: GameFiles, hlvs_check: Any
) -> None:
    """League ``referee.py``: the pose is read only for the GameController's goalkeeper (player
    1 unless a robot declares itself goalkeeper), so the league plays ``teams/bitbots.json``."""
    _bitbots_like(game_files.red)
    path = game_files.write()
    problems = check_game(path)  # KID: the match's and the pre-flight's check
    assert not [p for p in problems if p.severity == "error"], problems
    assert not _problems_at(problems, KEEPER)
    upload = check_team(path.parent / "team_red.json")  # the upload's check: no class yet
    assert not [p for p in upload if p.severity == "error"], upload
    for klass in (FieldClass.KID, FieldClass.ADULT):
        assert not _problems_at(check_team(path.parent / "team_red.json", field_class=klass),
                                KEEPER)
    run = hlvs_check(path)
    assert run.code == 0, run.out + run.err


@pytest.mark.parametrize(("x", "y"), [(-1.0, 0.0), (-4.4, 2.9), (1.0, 0.0)])
def test_the_goalkeepers_own_pose_away_from_goal_is_a_warning_in_every_check(
    game_files: GameFiles, x: float, y: float
) -> None:
    """League ``referee.py``: a shoot-out goalkeeper away from its goal line is judged in the
    shoot-out (it must stay on or behind the line between the posts); the file is played."""
    game_files.blue["players"]["1"][KEEPER]["translation"] = [x, y, 0.43]
    path = game_files.write()
    loaded = load_game(path)  # no error: the match and the pre-flight accept it
    warnings = _problems_at(list(loaded.warnings), f"/players/1/{KEEPER}")
    assert [w.severity for w in warnings] == ["warning"]
    assert "shoot-out" in warnings[0].message
    upload = check_team(Path(path.parent / "team_blue.json"))
    assert not [p for p in upload if p.severity == "error"]
    assert (x >= 0) == bool(_problems_at(upload, f"/players/1/{KEEPER}"))
