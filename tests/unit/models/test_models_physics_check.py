"""The committee's model check: catalogue servos, arm reach per chain, joint ranges, inertia."""

from __future__ import annotations

import json
from pathlib import Path

from orchestrator.config.robot_models import check_model
from simulator.world.robots.team import load_team_model
from simulator.world.robots.team.rulebook import check

from .conftest import WOLFGANG, box_robot, edit_manifest


def _errors(folder: Path, *, official: bool = False) -> list[str]:
    problems, _ = check_model(folder, official=official)
    return [f"{p.pointer}: {p.message}" for p in problems if p.severity == "error"]


def test_wolfgang_reach_is_its_own_arm() -> None:
    measurements, problems = check(load_team_model(WOLFGANG))
    assert problems == []
    assert 0.28 < measurements.arm_m < 0.30  # each arm's own chain, not shoulder to other hand
    # every chain from the torso without a foot: both arms and the head
    assert set(measurements.arm_chains_m) == {"l_shoulder", "r_shoulder", "neck"}
    assert measurements.arm_chains_m["neck"] < 0.2
    assert measurements.servos["LKnee"] == "XM540-W270@14.8V"


def test_arms_reaching_far_sideways_pass_when_each_arm_is_within_the_limit(
    tmp_path: Path,
) -> None:
    folder = box_robot(tmp_path / "wide", height_m=0.6, arms_sideways_m=0.33)
    measurements, problems = check(load_team_model(folder))
    limit = 1.2 * measurements.top_m
    span = 0.3 + 0.33  # shoulder to shoulder plus one arm: what a whole-body measure would see
    assert span > limit
    assert max(measurements.arm_chains_m.values()) <= limit
    assert [p for p in problems if p.where == "arm length"] == []
    too_long = box_robot(tmp_path / "long", height_m=0.6, arms_sideways_m=0.5)
    assert any(e.startswith("arm length:") for e in _errors(too_long))


def test_a_servo_above_its_catalogue_entry_is_refused(tmp_path: Path) -> None:
    folder = tmp_path / "wolfgang"
    import shutil

    shutil.copytree(WOLFGANG, folder)
    manifest = json.loads((folder / "robot_model.json").read_text())
    manifest["motors"][9]["max_torque_nm"] = 25.0  # LHipRoll, an MX-106 at 14.8 V: 10 N m
    edit_manifest(folder, motors=manifest["motors"])
    errors = _errors(folder)
    assert errors == [
        "/motors/9/max_torque_nm: LHipRoll (joint LHipRoll): max_torque_nm 25 is above the "
        "catalogue's 10 for MX-106@14.8V (rule: servos from the league catalogue)"
    ]
    # the world never gives it more than the catalogue's figure
    assert load_team_model(folder).motor("LHipRoll").max_torque_nm == 10.0


def test_free_form_servos_warn_in_friendlies_and_are_refused_in_official_matches(
    tmp_path: Path,
) -> None:
    folder = box_robot(
        tmp_path / "free",
        height_m=0.7,
        motor={"kp": 40, "max_torque_nm": 8, "max_velocity_rad_s": 6},
    )
    problems, _ = check_model(folder)
    warnings = [p for p in problems if p.severity == "warning"]
    assert not [p for p in problems if p.severity == "error"]
    assert {p.pointer for p in warnings} >= {"/motors/0/servo", "/motors/0/kp"}
    official = _errors(folder, official=True)
    assert any(
        e.startswith("/motors/0/servo: hip_l (joint hip_l) names no catalogue servo")
        for e in official
    )
    assert any("free-form gain kp" in e for e in official)


def test_unknown_servo_names_the_catalogue(tmp_path: Path) -> None:
    folder = box_robot(tmp_path / "unknown", height_m=0.7, motor={"servo": "MX-65"})
    errors = _errors(folder)
    assert errors and errors[0].startswith("/motors/0/servo: 'MX-65' is not in the league servo")
    assert "MX-64@14.8V" in errors[0]


def test_joint_without_range_and_implausible_inertia_are_refused(tmp_path: Path) -> None:
    folder = box_robot(tmp_path / "odd", height_m=0.7)
    xml = (folder / "robot.xml").read_text()
    xml = xml.replace(
        '<joint name="neck" type="hinge" axis="0 1 0" range="-1 1"/>',
        '<joint name="neck" type="hinge" axis="0 1 0"/>',
    )
    xml = xml.replace('<body name="foot_l" pos', '<body name="foot_l" pos', 1).replace(
        '<geom type="box" size="0.08 0.04 0.01" pos="0.02 0 0"/></body></body><body name="hip_r"',
        '<inertial pos="0 0 0" mass="0.2" diaginertia="1e-12 1e-12 1e-12"/>'
        '<geom type="box" size="0.08 0.04 0.01" pos="0.02 0 0" mass="0"/></body></body>'
        '<body name="hip_r"',
    )
    (folder / "robot.xml").write_text(xml)
    errors = _errors(folder)
    assert any(e.startswith("joint range of neck:") for e in errors), errors
    assert any(e.startswith("inertia of foot_l:") for e in errors), errors
