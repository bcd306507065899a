"""The servo catalogue covers the league robots' servos, each figure with its source, and every
joint gets its servo's reflected rotor inertia."""

from __future__ import annotations

import json
import math

import pytest

from simulator.world.servos import catalogue, find_servo
from simulator.world.servos.catalogue import FOLDER, RPM


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
        ("XH430-W350@12V", 3.4, 30, 353.5, 0.082),
        ("XH430-V210@24V", 2.6, 52, 212.6, 0.082),
        ("XH430-V350@24V", 3.3, 31, 353.5, 0.082),
        ("MX-64(2.0)@14.8V", 7.3, 78, 200, 0.135),  # the protocol 2.0 firmware, same servo
        ("MX-106(2.0)", 10.0, 55, 225, 0.153),
        ("XM540-W270@14.8V", 12.9, 37, 272.5, 0.165),
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
