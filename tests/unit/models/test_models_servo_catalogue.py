"""The servo catalogue covers the league robots' servos, each figure with its source, and every
joint gets its servo's reflected rotor inertia."""

from __future__ import annotations

import json
import math
import re
from collections import defaultdict
from pathlib import Path

import pytest

from orchestrator.config.robot_models import check_model
from simulator.world.servos import catalogue, find_servo
from simulator.world.servos.catalogue import FOLDER, RPM
from tests.unit.models.conftest import box_robot


def test_every_entry_has_its_sources_mass_and_rotor_inertia() -> None:
    for path in sorted(FOLDER.glob("*.json")):
        raw = json.loads(path.read_text())
        assert raw["source"].startswith("https://emanual.robotis.com/docs/en/dxl/"), path.name
        assert raw["mass_kg"] > 0 and raw["rotor_inertia_kg_m2"] > 0, path.name
        assert "estimated" in raw["rotor_inertia_source"], path.name
    for servo in catalogue().values():
        assert servo.armature_kg_m2 == pytest.approx(
            servo.rotor_inertia_kg_m2 * servo.gear_ratio**2
        )


@pytest.mark.parametrize(
    ("name", "stall_nm", "rpm", "ratio", "mass_kg"),
    [
        ("XM430-W350@12V", 4.1, 46, 353.5, 0.082),  # ROBOTIS OP3
        ("XM430-W210@12V", 3.0, 77, 212.6, 0.082),
        ("XM430-W210@14.8V", 3.7, 95, 212.6, 0.082),
        ("XH430-W210@11.1V", 2.2, 46, 212.6, 0.082),
        ("XH430-W210@14.8V", 3.1, 62, 212.6, 0.082),
        ("XH430-W350@12V", 3.4, 30, 353.5, 0.082),
        ("XH430-V210@24V", 2.6, 52, 212.6, 0.082),
        ("XH430-V350@24V", 3.3, 31, 353.5, 0.082),
        ("MX-64(2.0)@14.8V", 7.3, 78, 200, 0.135),  # the protocol 2.0 firmware, same servo
        ("MX-106(2.0)", 10.0, 55, 225, 0.153),
        ("XM540-W270@14.8V", 12.9, 37, 272.5, 0.165),
        ("XM540-W150@11.1V", 6.9, 50, 152.3, 0.165),
        ("XH540-W150@12V", 7.1, 70, 152.3, 0.165),
        ("XH540-W150@14.8V", 8.5, 86, 152.3, 0.165),
        ("XH540-W270@11.1V", 9.2, 36, 272.5, 0.165),
        ("XH540-W270@12V", 9.9, 39, 272.5, 0.165),
        ("XH540-W270", 11.7, 46, 272.5, 0.165),
        ("XH540-V150", 6.4, 60, 152.3, 0.165),
        ("XH540-V270@24V", 9.2, 34, 272.5, 0.165),
        ("PM42-010-S260-R", 1.7, 28.0, 257.019, 0.27),  # continuous torque to 26.0 rpm
        ("PH42-020-S300-R", 5.1, 32.7, 303.75, 0.34),
        ("PH54-100-S500-R", 25.3, 33.3, 501.923, 0.74),
        ("PH54-200-S500-R", 44.7, 33.1, 501.923, 0.855),
        ("PM54-060-S250-R", 10.1, 33.1, 251.417, 0.855),  # continuous torque to 28.3 rpm
        ("PM54-040-S250-R", 3.9, 28.4, 251.417, 0.71),
    ],
)
def test_datasheet_figures(
    name: str, stall_nm: float, rpm: float, ratio: float, mass_kg: float
) -> None:
    servo = find_servo(name)
    assert servo is not None, name
    assert (servo.stall_torque_nm, servo.gear_ratio, servo.mass_kg) == (stall_nm, ratio, mass_kg)
    assert math.isclose(servo.no_load_speed_rad_s, rpm * RPM)


def test_the_op3s_servo_reflects_the_menagerie_armature() -> None:
    # the estimate's reference: 0.045 kg m^2 on every XM430-W350 joint of the Menagerie's OP3
    servo = find_servo("XM430-W350")
    assert servo is not None and servo.armature_kg_m2 == pytest.approx(0.045, rel=0.01)


# size class (by model name) -> (mass range kg, highest-voltage stall torque range N m)
SIZE_CLASSES = {
    r"^X[MHW]430-": ((0.075, 0.09), (2.0, 5.0)),
    r"^X[MHW]540-": ((0.16, 0.19), (6.0, 13.0)),
    r"^MX-": ((0.07, 0.16), (2.5, 10.5)),
    r"^P[HM]42-": ((0.25, 0.35), (1.0, 6.0)),
    r"^P[HM]54-": ((0.7, 0.9), (3.5, 45.0)),
}


def test_every_model_is_plausible_for_its_size_class() -> None:
    """Mass and torque within the range of servos of the same case size, the motor's own speed
    (no-load speed x gear ratio) that of a small DC motor, and torque and speed rising with the
    voltage: a figure typed from the wrong row or column fails here."""
    for path in sorted(FOLDER.glob("*.json")):
        model = json.loads(path.read_text())["model"]
        ranges = [r for pattern, r in SIZE_CLASSES.items() if re.match(pattern, model)]
        assert len(ranges) == 1, f"{model}: no size class"
        (mass_lo, mass_hi), (torque_lo, torque_hi) = ranges[0]
        variants = sorted(
            (s for s in catalogue().values() if s.model == model), key=lambda s: s.voltage_v
        )
        top = variants[-1]
        assert mass_lo <= top.mass_kg <= mass_hi, model
        assert torque_lo <= top.stall_torque_nm <= torque_hi, model
        motor_rpm = top.no_load_speed_rad_s / RPM * top.gear_ratio
        assert 5_000 <= motor_rpm <= 25_000, (model, motor_rpm)
        for low, high in zip(variants, variants[1:], strict=False):
            assert low.stall_torque_nm < high.stall_torque_nm, model
            assert low.no_load_speed_rad_s < high.no_load_speed_rad_s, model


def test_two_gear_ratios_of_one_motor_turn_it_at_the_same_speed() -> None:
    """XH540-W150 and XH540-W270 (and every such pair) share their motor: the datasheets'
    no-load speed x gear ratio agree within 5 %."""
    motors: dict[str, list[float]] = defaultdict(list)
    for servo in catalogue().values():
        found = re.match(r"^(X[MHW]\d{3}-[A-Z])\d+$", servo.model)
        if found and servo.voltage_v in (14.8, 24.0):
            motors[found.group(1)].append(servo.no_load_speed_rad_s / RPM * servo.gear_ratio)
    pairs = {k: v for k, v in motors.items() if len(v) >= 2}
    assert {"XH430-W", "XH540-W", "XM430-W", "XM540-W", "XH540-V"} <= set(pairs), pairs
    for motor, speeds in pairs.items():
        assert max(speeds) / min(speeds) < 1.05, (motor, speeds)


@pytest.mark.parametrize(
    "name", ["XH430-W210@12V", "XH540-W150@14.8V", "XH540-W270@11.1V", "PM42-010-S260-R"]
)
def test_official_checks_accept_a_robot_on_the_new_servos(tmp_path: Path, name: str) -> None:
    folder = box_robot(tmp_path / "box", height_m=0.7, motor={"servo": name})
    problems, measured = check_model(folder, official=True)
    assert measured is not None
    assert not [str(p) for p in problems if p.severity == "error"]
