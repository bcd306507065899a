"""team_config.json names a robot model package by path: resolved, checked, mounted, named."""

from __future__ import annotations

import json
from pathlib import Path

from orchestrator.config import FieldClass, check_team, load_team
from orchestrator.config.robot_models import container_path, spec_model
from orchestrator.match.layout import simulator_request
from orchestrator.match.scrimmage import team_file
from tests.unit.models.conftest import WOLFGANG, box_robot, edit_manifest


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
        and "kid-default" in t
        and "robot_model.json" in t
        for t in text
    ), text


def test_a_model_that_breaks_the_rules_cannot_be_used(tmp_path: Path) -> None:
    box_robot(tmp_path / "tall", height_m=1.4)
    problems = [str(p) for p in check_team(_team(tmp_path, "tall"), field_class=FieldClass.KID)]
    assert len([p for p in problems if "/players/" in p and "height: H = 1.4" in p]) == 2


def test_the_simulator_container_reads_each_package_once_read_only(tmp_path: Path) -> None:
    from orchestrator.match.plan import plan_from_game  # noqa: F401  (import check)

    request = simulator_request(
        _plan_stub(),
        prefix="hlvs-x",
        image="sim:1",
        match_dir=tmp_path,
        attachments=(),
        extra_labels={},
        model_dirs=(WOLFGANG,),
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
    adult = team_file(
        "Bots", "registry.example/bots:1", 2, model="adult-default", field_class=FieldClass.ADULT
    )
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


FREE_MOTOR = {"kp": 40, "max_torque_nm": 8, "max_velocity_rad_s": 6}


def test_free_servos_are_refused_for_an_official_match_and_a_warning_in_a_friendly(
    tmp_path: Path,
) -> None:
    """A package whose motors name no catalogue servo: the team file of an official match is
    refused (naming the joint and the rule), a friendly's plays with a warning."""
    box_robot(tmp_path / "free", height_m=0.7, motor=FREE_MOTOR)
    team = _team(tmp_path, "free")
    official = check_team(team, field_class=FieldClass.KID, official=True)
    errors = [str(p) for p in official if p.severity == "error"]
    assert any(
        "/players/1/model: the robot model cannot be used" in e
        and "hip_l (joint hip_l)" in e
        and "not for an official match" in e
        and "servos from the league catalogue" in e
        for e in errors
    ), errors
    friendly = check_team(team, field_class=FieldClass.KID)
    assert not [p for p in friendly if p.severity == "error"]
    assert any(
        "for friendlies only (refused in official matches)" in str(p)
        for p in friendly
        if p.severity == "warning"
    )


def test_robots_of_the_other_size_class_are_refused_for_an_official_match(
    tmp_path: Path,
) -> None:
    """adult-default in a kid game, a package that says it is adult-size in a kid game: an
    error in an official match naming what fits, a warning in a friendly."""
    adult = _team(tmp_path, "adult-default")
    errors = [str(p) for p in check_team(adult, field_class=FieldClass.KID, official=True)]
    assert len(errors) == 2 and all(
        "adult-default is a robot model of the adult size class in a game of the kid size class"
        in e
        and "expected a model of the kid size class: kid-default" in e
        for e in errors
    ), errors
    warnings = check_team(adult, field_class=FieldClass.KID)
    assert [p.severity for p in warnings] == ["warning", "warning"]
    assert "refused in official matches" in warnings[0].message
    assert not check_team(adult, field_class=FieldClass.ADULT, official=True)
    box_robot(tmp_path / "big", height_m=1.4)
    edit_manifest(tmp_path / "big", **{"class": "adult"})
    (tmp_path / "p").mkdir()
    package = _team(tmp_path / "p", "../big")
    found = [str(p) for p in check_team(package, field_class=FieldClass.KID, official=True)]
    assert any("of the adult size class in a game of the kid size class" in e for e in found), found
    assert not check_team(package, field_class=FieldClass.ADULT, official=True)


def test_an_official_game_checks_its_teams_as_official(tmp_path: Path) -> None:
    """game.json's ``official`` reaches the team files' model checks."""
    from orchestrator.config import check_game

    box_robot(tmp_path / "free", height_m=0.7, motor=FREE_MOTOR)
    examples = WOLFGANG.parents[1] / "kid_4v4_official"
    game = json.loads((examples / "game.json").read_text())
    for color in ("red", "blue"):
        team = json.loads((examples / f"team_{color}.json").read_text())
        if color == "red":
            for player in team["players"].values():
                player["model"] = "free"
        (tmp_path / f"team_{color}.json").write_text(json.dumps(team))
    for official, severity in ((True, "error"), (False, "warning")):
        game["official"] = official
        (tmp_path / "game.json").write_text(json.dumps(game))
        found = [p for p in check_game(tmp_path / "game.json") if "/model" in p.pointer]
        assert found and {p.severity for p in found} == {severity}, found
