"""``hlvs check SCHEDULE`` opens everything a match will need and reports every problem at once."""

from __future__ import annotations

import json
from datetime import UTC, datetime
from pathlib import Path

import pytest

from hlvs.cli import main
from orchestrator.config.schedule_check import check_schedule
from tests.unit.schedule.test_schedule import write_credentials

EXAMPLES = Path(__file__).resolve().parents[3] / "configs" / "examples" / "scrimmage_1v1"


def _cup(tmp: Path, body: str) -> Path:
    team = json.loads((EXAMPLES / "team_red.json").read_text())
    (tmp / "ants.json").write_text(json.dumps(team))
    for player in team["players"].values():
        player["dockerTag"] = 5
    (tmp / "bees.json").write_text(json.dumps(team))
    write_credentials(tmp / "logs.json")
    path = tmp / "cup.yaml"
    path.write_text(body)
    return path


BROKEN = """
name: cup
simulator_slots: 0
game_defaults:
  stepping: lockstp
  timing: {half_duraton_s: 8}
teams:
  - {name: ants, id: 1, config: ants.json}
  - {name: bees, id: 2, config: bees.json, credentials: nope.json}
matches:
  - {id: m1, red: ants, blue: bess, stream_start: "+1h"}
  - {id: m2, red: ants, blue: bees, stream_start: "+2h", kind: knockout}
"""


def test_every_problem_is_reported_at_once(tmp_path: Path) -> None:
    path = _cup(tmp_path, BROKEN)
    found = {(Path(p.file).name, p.pointer): p for p in check_schedule(path)}
    assert "schema" not in str(found)
    assert ("cup.yaml", "/simulator_slots") in found  # a schema error ...
    unknown = found[("cup.yaml", "/matches/0/blue")]  # ... does not hide the cross-checks
    assert "unknown team 'bess'" in unknown.message and unknown.suggestion == '"bees"'
    assert "file not found" in found[("cup.yaml", "/teams/1/credentials")].message
    assert "has no log target" in found[("cup.yaml", "/teams/0/credentials")].message
    assert "a string" in found[("bees.json", "/players/1/dockerTag")].expected
    assert found[("cup.yaml", "/game_defaults/stepping")].suggestion == '"lockstep"'
    typo = found[("cup.yaml", "/game_defaults/timing/half_duraton_s")]
    assert typo.suggestion == '"half_duration_s"'
    assert all(p.severity == "error" for p in found.values())


def test_a_half_must_keep_the_minimum_of_play(tmp_path: Path,
                                              capsys: pytest.CaptureFixture[str]) -> None:
    fixed = (BROKEN.replace("simulator_slots: 0", "simulator_slots: 1")
             .replace("lockstp", "lockstep").replace("half_duraton_s", "half_duration_s")
             .replace(", credentials: nope.json", ", credentials: logs.json")
             .replace("config: ants.json}", "config: ants.json, credentials: logs.json}")
             .replace("bess", "bees"))
    path = _cup(tmp_path, fixed)
    (tmp_path / "bees.json").write_text((tmp_path / "ants.json").read_text())
    problems = check_schedule(path)
    assert [(p.pointer, p.severity) for p in problems] == [
        ("/game_defaults/timing/half_duration_s", "error")]
    assert "a half of 8 s leaves 8 s of play" in problems[0].message
    assert main(["check", str(path)]) == 2
    assert "/game_defaults/timing/half_duration_s" in capsys.readouterr().out
    path.write_text(fixed.replace("half_duration_s: 8", "half_duration_s: 60"))
    assert check_schedule(path) == []
    assert main(["check", str(path)]) == 0
    assert "ok (schedule)" in capsys.readouterr().out


def test_schedule_run_refuses_what_check_refuses(tmp_path: Path) -> None:
    path = _cup(tmp_path, BROKEN)
    assert main(["schedule", "run", str(path), "--state", str(tmp_path / "s.sqlite")]) == 2
    assert not (tmp_path / "s.sqlite").exists()


def test_an_official_schedule_checks_its_teams_as_official(tmp_path: Path) -> None:
    """``official: true`` in game_defaults makes every match official: a team of adult-default
    robots on the kid field is refused before the tournament starts, not at its match."""
    fixed = (BROKEN.replace("simulator_slots: 0", "simulator_slots: 1")
             .replace("lockstp", "lockstep").replace("half_duraton_s: 8", "half_duration_s: 60")
             .replace(", credentials: nope.json", ", credentials: logs.json")
             .replace("config: ants.json}", "config: ants.json, credentials: logs.json}")
             .replace("bess", "bees"))
    path = _cup(tmp_path, fixed)
    team = json.loads((tmp_path / "ants.json").read_text())
    for player in team["players"].values():
        player["model"] = "adult-default"
    (tmp_path / "bees.json").write_text(json.dumps(team))
    friendly = check_schedule(path)
    assert friendly and {p.severity for p in friendly} == {"warning"}
    path.write_text(fixed.replace("  stepping: lockstep", "  stepping: lockstep\n  official: true"))
    official = [p for p in check_schedule(path) if p.severity == "error"]
    assert official and all(Path(p.file).name == "bees.json" and "adult size class" in p.message
                            for p in official), official


def test_what_would_go_wrong_on_the_day_is_refused(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A team without a log target, a match whose stream has started, two streams of one team
    at once, a round robin whose interval is shorter than its stream."""
    body = """
name: cup
teams:
  - {name: ants, id: 1, config: ants.json, credentials: logs.json}
  - {name: bees, id: 2, config: bees.json}
  - {name: wasps, id: 3, config: ants.json, credentials: logs.json}
matches:
  - {id: m1, red: ants, blue: bees, stream_start: "2020-05-01T10:00:00+00:00"}
  - {id: m2, red: ants, blue: wasps, stream_start: "+2h", stream_length_s: 1800}
  - {id: m3, red: wasps, blue: bees, stream_start: "+135m", stream_length_s: 1800}
fixtures:
  round_robin: {teams: [ants, bees, wasps], first_stream: "+1d", interval_s: 1200,
                stream_length_s: 1800}
"""
    path = _cup(tmp_path, body)
    found = {p.pointer: p for p in check_schedule(path, now=datetime.now(UTC))}
    assert "'bees' has no log target" in found["/teams/1/credentials"].message
    assert "in the past" in found["/matches/0/stream_start"].message
    overlap = found["/matches/2/stream_start"].message
    assert "'wasps' also plays m2" in overlap and "overlaps" in overlap
    assert "/matches/1/stream_start" not in found
    assert "shorter than a stream (1800 s)" in found["/fixtures/round_robin/interval_s"].message
    assert all(p.severity == "error" for p in found.values())
    assert main(["check", str(path)]) == 2
    out = capsys.readouterr().out
    assert "in the past" in out and "no log target" in out
    assert main(["schedule", "run", str(path), "--state", str(tmp_path / "s.sqlite")]) == 2
    assert not (tmp_path / "s.sqlite").exists()
    # without a clock (hlvs schedule apply mid-tournament) a past match is not a problem
    assert "/matches/0/stream_start" not in {p.pointer for p in check_schedule(path)}
