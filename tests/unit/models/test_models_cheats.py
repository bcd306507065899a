"""Models made to buy an advantage are refused by the official check, each naming its rule; and
what ``hlvs check`` measures for a technical committee (mass split, servo mass, per-chain reach,
collision coverage)."""

from __future__ import annotations

import json
import re
import shutil
from pathlib import Path

from orchestrator.config.robot_models import check_model
from simulator.world.robots import robot_model
from simulator.world.selfcollision import excluded_pairs

from .conftest import box_robot, edit_manifest

URDF = Path("wolfgang_description") / "urdf" / "robot.urdf"


def _errors(folder: Path) -> list[str]:
    problems, _ = check_model(folder, official=True)
    return [f"{p.pointer}: {p.message}" for p in problems if p.severity == "error"]


def test_the_untouched_models_pass(wolfgang_copy: Path, tmp_path: Path) -> None:
    assert _errors(wolfgang_copy) == []
    assert _errors(box_robot(tmp_path / "box", height_m=0.7)) == []


def test_lead_in_the_feet_is_refused(wolfgang_copy: Path) -> None:
    urdf = wolfgang_copy / URDF
    text = urdf.read_text()
    foot = text.index('<link name="l_foot">')
    text = text[:foot] + text[foot:].replace(
        '<mass value="0.26824"/>', '<mass value="5.26824"/>', 1
    )
    urdf.write_text(text)
    errors = _errors(wolfgang_copy)
    lead = [e for e in errors if "(rule: mass per link plausible for its size)" in e]
    assert len(lead) == 1 and lead[0].startswith("mass of l_foot: 5.275 kg in the "), errors


def test_an_arm_tagged_head_is_measured_as_an_arm(wolfgang_copy: Path) -> None:
    urdf = wolfgang_copy / URDF
    elbow = '<origin rpy="-1.5708 3.08909e-14 1.5708" xyz="-0.024 -0.144 -0.0235"/>'
    text = urdf.read_text()
    assert text.count(elbow) == 1  # the left elbow: the forearm 0.28 m farther
    urdf.write_text(text.replace(elbow, elbow.replace("-0.144", "-0.424")))
    manifest = json.loads((wolfgang_copy / "robot_model.json").read_text())
    parts = manifest["parts"]
    parts["arm"].remove("l_shoulder")
    parts["head"].append("l_shoulder")
    edit_manifest(wolfgang_copy, parts=parts)
    errors = _errors(wolfgang_copy)
    assert any(re.match(r"arm length: Harm = 0\.5\d\d m is above 1\.2 Htop", e) for e in errors), (
        errors
    )
    _, measured = check_model(wolfgang_copy, official=True)
    assert measured is not None and measured.arm_chains_m["l_shoulder"] > 0.5


def test_a_model_lighter_than_its_servos_is_refused(wolfgang_copy: Path) -> None:
    manifest = json.loads((wolfgang_copy / "robot_model.json").read_text())
    for motor in manifest["motors"]:
        motor["servo"] = "PH54-200-S500-R"  # 44.7 N m, 0.855 kg each: 17.1 kg of servos
    edit_manifest(wolfgang_copy, motors=manifest["motors"])
    errors = _errors(wolfgang_copy)
    assert (
        "mass of the servos: the model weighs 6.117 kg, less than its servos alone (17.100 kg, "
        "the catalogue's mass of each motor's servo) (rule: the model weighs at least its servos)"
    ) in errors


def test_collision_shapes_switched_off_are_refused(tmp_path: Path) -> None:
    folder = box_robot(tmp_path / "ghost", height_m=0.7)
    xml = (folder / "robot.xml").read_text()
    feet = 'size="0.08 0.04 0.01"'
    xml = re.sub(
        r"<geom ([^>]*?)/>",
        lambda m: (
            m.group(0)
            if feet in m.group(1)
            else f'<geom {m.group(1)} contype="0" conaffinity="0"/>'
        ),
        xml,
    )
    (folder / "robot.xml").write_text(xml)
    errors = _errors(folder)
    uncovered = [e for e in errors if "(rule: every link that has mass has collision shapes" in e]
    assert any(e.startswith("collision shapes of torso:") for e in uncovered), errors
    assert any(e.startswith("collision shapes of hip_l:") for e in uncovered), errors
    _, measured = check_model(folder, official=True)
    assert measured is not None and measured.collision_coverage < 0.5
    assert "torso" in measured.uncovered_parts


def test_a_hidden_box_reaching_the_other_leg_neither_passes_nor_stops_its_collisions(
    tmp_path: Path,
) -> None:
    folder = box_robot(tmp_path / "skirt", height_m=0.7)
    xml = (folder / "robot.xml").read_text()
    hip = (
        '<body name="hip_l" pos="0 0.06 0.315">'
        '<joint name="hip_l" type="hinge" axis="0 1 0" range="-1 1"/>'
    )
    assert hip in xml
    xml = xml.replace(hip, hip + '<geom type="box" size="0.02 0.04 0.05" pos="0 -0.06 -0.15"/>')
    (folder / "robot.xml").write_text(xml)
    errors = _errors(folder)
    assert any(
        e.startswith("self-collision of hip_l and hip_r: their collision shapes overlap in the "
                     "zero pose") and "(rule: self-collision is excluded only between a parent "
        "and its child, or links of one chain" in e
        for e in errors
    ), errors  # fmt: skip
    pairs = excluded_pairs(robot_model(str(folder.resolve())))
    assert ("link:hip_l", "link:hip_r") not in pairs and ("link:hip_r", "link:hip_l") not in pairs


def test_joint_armature_is_bounded_by_the_servos(wolfgang_copy: Path, tmp_path: Path) -> None:
    within = tmp_path / "within"
    shutil.copytree(wolfgang_copy, within)
    edit_manifest(wolfgang_copy, joint_armature=0.5)
    errors = [e for e in _errors(wolfgang_copy) if e.startswith("/joint_armature:")]
    assert errors and all("(rule: armature within a factor 2" in e for e in errors)
    assert errors[0].startswith("/joint_armature: 0.5 kg m^2 on HeadPan (MX-64@14.8V) is outside")
    edit_manifest(within, joint_armature=0.05)  # within 2x of MX-64, MX-106, XM540
    assert [e for e in _errors(within) if e.startswith("/joint_armature:")] == []


def test_the_committee_reads_what_was_measured(wolfgang_copy: Path) -> None:
    _, measured = check_model(wolfgang_copy, official=True)
    assert measured is not None
    data = measured.to_json()
    assert data["servo_mass_kg"] == 2.94  # 8 MX-64, 10 MX-106, 2 XM540-W270
    assert data["collision_coverage"] == 1.0 and data["uncovered_parts"] == []
    split = data["mass_split_kg"]
    assert set(split) == {"arm", "foot", "hand", "head", "leg", "torso"}
    assert abs(sum(split.values()) - data["mass_kg"]) < 1e-3
    assert set(data["arm_chains_m"]) == {"l_shoulder", "r_shoulder", "neck"}
