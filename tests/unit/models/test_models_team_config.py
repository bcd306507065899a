"""team_config.json names a robot model package by path: resolved, checked, mounted, named."""

from __future__ import annotations

import json
from pathlib import Path

from orchestrator.config import FieldClass, check_team, load_team
from orchestrator.config.robot_models import container_path, spec_model
from orchestrator.match.layout import simulator_request
from orchestrator.match.scrimmage import team_file
from tests.unit.models.conftest import WOLFGANG, box_robot


def _team(folder: Path, model: str) -> Path:
    document = team_file("Bots", "registry.example/bots:1", 2, goalie_first=True, model=model)
    path = folder / "team_config.json"
    path.write_text(json.dumps(document))
    return path


def test_relative_model_path_resolved_against_the_team_file(tmp_path: Path) -> None:
    box_robot(tmp_path / "models" / "box", height_m=0.7)
    team = load_team(_team(tmp_path, "models/box"), field_class=FieldClass.KID).team
    assert {p.model for p in team.players} == {str(tmp_path / "models" / "box")}
    assert spec_model(team.players[0].model) == container_path(str(tmp_path / "models/box"))
    assert spec_model("kid-default") == "kid-default"


def test_missing_package_names_the_folder_and_what_was_expected(tmp_path: Path) -> None:
    problems = check_team(_team(tmp_path, "./nowhere"), field_class=FieldClass.KID)
    text = [str(p) for p in problems]
    assert any(
        "/players/1/model: no robot model package at " + str(tmp_path / "nowhere") in t
        and "kid-default" in t and "robot_model.json" in t
        for t in text
    ), text


def test_a_model_that_breaks_the_rules_cannot_be_used(tmp_path: Path) -> None:
    box_robot(tmp_path / "tall", height_m=1.4)
    problems = [str(p) for p in check_team(_team(tmp_path, "tall"), field_class=FieldClass.KID)]
    assert len([p for p in problems if "/players/" in p and "height: H = 1.4" in p]) == 2


def test_the_simulator_container_reads_each_package_once_read_only(tmp_path: Path) -> None:
    from orchestrator.match.plan import plan_from_game  # noqa: F401  (import check)

    request = simulator_request(
        _plan_stub(), prefix="hlvs-x", image="sim:1", match_dir=tmp_path, attachments=(),
        extra_labels={}, model_dirs=(WOLFGANG,),
    )
    models = [m for m in request.mounts if m.target.startswith("/opt/hlvs/team-models/")]
    assert [(m.source, m.read_only) for m in models] == [(WOLFGANG, True)]
    assert models[0].target == container_path(str(WOLFGANG))


def _plan_stub() -> object:
    class Plan:
        match_id = "m1"

    return Plan()


def test_scrimmage_stub_is_told_the_built_in_model_it_drives(tmp_path: Path) -> None:
    """A stub robot runs the gait of the model on its command line and plays on the field it is
    told: every stub of an adult team is told ``--model adult-default`` and the field; a team's
    model package is not a model the stub knows, so only the field is added."""
    adult = team_file("Bots", "registry.example/bots:1", 2, model="adult-default",
                      field_class=FieldClass.ADULT)
    commands = [p["dockerCmd"] for p in adult["players"].values()]
    assert all(c.endswith(" --model adult-default --field-class adult") for c in commands), commands
    box_robot(tmp_path / "box", height_m=0.7)
    package = team_file("Bots", "registry.example/bots:1", 2, model=str(tmp_path / "box"))
    commands = [p["dockerCmd"] for p in package["players"].values()]
    assert not any("--model" in c for c in commands)
    assert all(c.endswith(" --field-class kid") for c in commands), commands
    plain = team_file("Bots", "registry.example/bots:1", 2)
    commands = [p["dockerCmd"] for p in plain["players"].values()]
    assert all(c.endswith(" --model kid-default --field-class kid") for c in commands), commands
