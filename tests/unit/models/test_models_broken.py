"""Broken model packages: each gives precise problems (file, where, what), never a traceback."""

from __future__ import annotations

import io
import json
from pathlib import Path

import pytest

from hlvs.commands.check import check_file
from simulator.errors import ModelError
from simulator.world.robots.team import load_team_model
from tests.unit.models.conftest import box_robot, edit_manifest


def _check(folder: Path) -> tuple[int, str]:
    out = io.StringIO()
    code = check_file(folder, out=out)
    return code, out.getvalue()


def test_missing_mesh_names_the_element_and_every_path_tried(wolfgang_copy: Path) -> None:
    (wolfgang_copy / "wolfgang_description" / "urdf" / "lense.stl").unlink()
    code, out = _check(wolfgang_copy)
    assert code == 2
    line = next(x for x in out.splitlines() if "lense.stl" in x)
    assert "robot.urdf" in line and "mesh file not found" in line
    assert str(wolfgang_copy / "wolfgang_description" / "urdf" / "lense.stl") in line


def test_malformed_xml_names_line_and_column(wolfgang_copy: Path) -> None:
    urdf = wolfgang_copy / "wolfgang_description" / "urdf" / "robot.urdf"
    urdf.write_text(urdf.read_text()[:5000])
    code, out = _check(wolfgang_copy)
    assert code == 2 and "malformed XML" in out and "line " in out and "robot.urdf" in out


def test_no_joints(tmp_path: Path) -> None:
    folder = box_robot(tmp_path / "rigid", height_m=0.7, joints=False)
    with pytest.raises(ModelError) as caught:
        load_team_model(folder)
    reasons = [p.reason for p in caught.value.problems]
    assert "the model has no movable joints (a robot needs motors)" in reasons
    assert "no joint 'hip_l' in the model" in reasons


def test_camera_beyond_the_field_of_view_limit(wolfgang_copy: Path) -> None:
    edit_manifest(
        wolfgang_copy,
        cameras=[{"name": "Camera", "link": "camera", "width": 320, "height": 240, "fov_rad": 3.5}],
    )
    code, out = _check(wolfgang_copy)
    assert code == 2
    assert "/cameras/0/fov_rad: horizontal field of view 3.500 rad (201 deg)" in out
    assert "above 3.142 rad (180 deg)" in out


def test_too_tall_for_its_class(tmp_path: Path) -> None:
    code, out = _check(box_robot(tmp_path / "tall", height_m=1.4))
    assert code == 2
    assert "height: H = 1.4" in out and "outside 0.4-1.0 m for the kid size class" in out
    assert _check(box_robot(tmp_path / "fits", height_m=0.7))[0] == 0


def test_manifest_mistakes_name_the_pointer(wolfgang_copy: Path) -> None:
    edit_manifest(wolfgang_copy, colour="red")
    code, out = _check(wolfgang_copy)
    assert code == 2 and "robot_model.json: /colour: unknown field; known fields: cameras" in out


def test_unknown_links_and_joints_get_a_suggestion(wolfgang_copy: Path) -> None:
    manifest = json.loads((wolfgang_copy / "robot_model.json").read_text())
    manifest["imu"] = {"link": "imu_frme"}
    manifest["motors"][0]["joint"] = "HedPan"
    (wolfgang_copy / "robot_model.json").write_text(json.dumps(manifest))
    code, out = _check(wolfgang_copy)
    assert code == 2
    assert "/imu/link: no link 'imu_frme' in the model; did you mean 'imu_frame'?" in out
    assert "/motors/0/joint: no joint 'HedPan' in the model; did you mean 'HeadPan'?" in out
    assert "joint 'HeadPan' is movable but not a motor" in out


def test_not_json_and_no_manifest(tmp_path: Path, wolfgang_copy: Path) -> None:
    (wolfgang_copy / "robot_model.json").write_text("{not json")
    code, out = _check(wolfgang_copy)
    assert code == 2 and "robot_model.json: not JSON" in out
    with pytest.raises(ModelError, match="no robot_model.json here"):
        load_team_model(tmp_path)


@pytest.mark.parametrize(
    ("edit", "severity", "where", "reason"),
    [
        ('<include file="arm.xml"/>', "error", "<include file='arm.xml'>", "included files are"),
        (
            '<equality><joint joint1="hip_l" joint2="hip_r"/></equality>',
            "error",
            "<equality>",
            "equality constraints (closed loops, coupled joints) are not supported",
        ),
        ('<keyframe><key name="k"/></keyframe>', "note", "<keyframe>", "ignored (1 element)"),
        (
            '<asset><texture name="t" type="2d" file="skin.png"/></asset>',
            "error",
            "<texture file='skin.png'>",
            "texture file not found",
        ),
    ],
)
def test_mjcf_elements_the_world_cannot_use_are_problem_lines(
    tmp_path: Path, edit: str, severity: str, where: str, reason: str
) -> None:
    folder = box_robot(tmp_path / "extra", height_m=0.7)
    xml = (folder / "robot.xml").read_text()
    (folder / "robot.xml").write_text(xml.replace("<worldbody>", edit + "<worldbody>", 1))
    try:
        problems = list(load_team_model(folder).notes)
    except ModelError as exc:
        problems = exc.problems
    assert any(
        p.severity == severity and p.where == where and reason in p.reason for p in problems
    ), problems
