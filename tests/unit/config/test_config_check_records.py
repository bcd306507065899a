"""``hlvs check --json`` writes problems and model measurements from their own dataclasses: the
fields in order, the root pointer as ``/``, lengths rounded to 0.1 mm."""

from __future__ import annotations

from hlvs.commands.check import FileReport
from orchestrator import Problem
from orchestrator.config.robot_models import describe
from simulator.world.robots.team.rulebook import Measurements

MEASURED = Measurements(
    size_class="kid",
    height_m=0.822849, leg_m=0.45104, head_m=0.16833, top_m=0.37181, arm_m=0.29277,
    foot_length_m=0.19, foot_width_m=0.10604, mass_kg=6.116749, cameras=1, max_fov_rad=1.04,
    motors=20, arm_chains_m={"l_shoulder": 0.29277}, servos={"LKnee": "XM540-W270@14.8V"},
)  # fmt: skip


def test_problems_are_written_field_by_field_with_the_root_as_slash() -> None:
    report = FileReport(file="team.json", kind="team", problems=[
        Problem("team.json", "", "not an object", expected="a JSON object"),
        Problem("team.json", "/players/0", "unknown field", severity="warning"),
    ])  # fmt: skip
    record = report.as_json()
    assert record["valid"] is False and "measurements" not in record
    first, second = record["problems"]
    assert list(first) == ["file", "pointer", "message", "expected", "suggestion", "severity"]
    assert first["pointer"] == "/" and first["expected"] == "a JSON object"
    assert second["pointer"] == "/players/0" and second["severity"] == "warning"


def test_measurements_are_written_rounded_and_first() -> None:
    record = FileReport(file="wolfgang", kind="robot model", measurements=MEASURED).as_json()
    assert list(record)[0] == "measurements"
    measurements = record["measurements"]
    assert measurements["size_class"] == "kid"
    assert measurements["height_m"] == 0.8228 and measurements["mass_kg"] == 6.1167
    assert measurements["arm_chains_m"] == {"l_shoulder": 0.2928}
    assert measurements["motors"] == 20 and measurements["servos"] == {"LKnee": "XM540-W270@14.8V"}
    assert MEASURED.height_m == 0.822849  # the measurements themselves keep every digit
    assert describe(MEASURED).startswith("H 0.8228 m, Hleg 0.451 m, Hhead 0.1683 m")
