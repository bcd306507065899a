"""The servo catalogue and the actuator model, measured (simulator.world.servo_tests)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from simulator.world.servo_tests import (
    backlash,
    breakaway_torque,
    no_load_speed,
    rig,
    stall_torque,
    step_error,
    webots_step,
)
from simulator.world.servos import catalogue, find_servo, servo

SAMPLE = ("MX-64@14.8V", "XW540-T140@14.8V", "PH54-200-S500-R@24V")


def test_catalogue_holds_the_datasheet_figures() -> None:
    mx106 = servo("MX-106@12V")
    assert (mx106.stall_torque_nm, mx106.gear_ratio) == (8.4, 225)
    assert mx106.no_load_speed_rad_s == pytest.approx(45 * 2 * math.pi / 60)
    assert mx106.encoder_resolution_rad == pytest.approx(2 * math.pi / 4096, rel=1e-6)
    assert mx106.backlash_rad == pytest.approx(math.radians(20 / 60), rel=1e-3)
    assert servo("MX-106").id == "MX-106@14.8V"  # a model alone: its highest voltage
    assert find_servo("MX-107") is None
    with pytest.raises(KeyError, match="MX-64@12V"):
        servo("MX-107")
    for entry in catalogue().values():
        assert entry.source.startswith("https://emanual.robotis.com/")
        assert entry.stall_torque_nm > 0 and entry.no_load_speed_rad_s > 0


@pytest.mark.parametrize("name", SAMPLE)
def test_no_load_speed_and_stall_torque_match_the_datasheet(name: str) -> None:
    entry = servo(name)
    assert no_load_speed(entry) == pytest.approx(entry.no_load_speed_rad_s, rel=0.05)
    assert stall_torque(entry) == pytest.approx(entry.stall_torque_nm, rel=0.05)


def test_position_step_follows_webots_motor_model() -> None:
    entry = servo("MX-106@14.8V")
    assert step_error(entry) <= 0.10  # P = 10, 0.3 rad
    assert step_error(entry, p=30.0, step=1.0) <= 0.10  # saturated: a ramp at the limit first
    # the analytic model itself: exponential with time constant 1/P below the knee
    assert webots_step(0.1, p=10.0, max_velocity=5.0, step=0.3) == pytest.approx(
        0.3 * (1 - math.exp(-1.0))
    )


def test_velocity_limit_bounds_position_control() -> None:
    """setVelocity bounds the speed of position control (the old servo passed it)."""
    r = rig(servo("MX-64@14.8V"))
    r.bank.set_pid(0, 100.0, 0.0, 0.0)
    r.bank.set_velocity(0, 2.0)
    r.bank.set_position(0, 2.0)
    speeds = [qdot for _t, _q, qdot in r.run(1.5)]
    assert max(speeds) <= 2.0 * 1.05
    assert r.data.qpos[0] == pytest.approx(2.0, abs=0.02)


def test_static_friction_and_backlash_by_measurement() -> None:
    entry = servo("MX-106@14.8V")
    assert breakaway_torque(entry) == pytest.approx(entry.static_friction_nm, rel=0.25)
    assert backlash(entry) == pytest.approx(entry.backlash_rad, rel=0.15)


def test_torque_mode_is_bounded_by_the_torque_speed_line() -> None:
    entry = servo("MX-64@14.8V")
    r = rig(entry)
    r.bank.set_torque(0, 100.0)  # clamped to the stall torque
    assert r.bank.torque[0] == entry.stall_torque_nm
    r.run(1.5)
    # spinning freely it cannot pass the no-load speed: the line leaves no torque there
    assert r.data.qvel[0] <= entry.no_load_speed_rad_s * 1.02


def test_limp_servo_gives_no_torque() -> None:
    r = rig(servo("MX-64@14.8V"))
    r.bank.set_limp(np.array([0]), True)
    r.bank.set_position(0, 1.0)
    r.run(0.5)
    assert r.data.actuator_force[0] == 0.0 and abs(r.data.qpos[0]) < 1e-6


def test_common_position_path_gives_the_forces_of_the_general_path() -> None:
    """Two identical worlds of walking-size robots, the same joint states and targets; in one
    a joint is held at its own target (the general path: same law), in the other nothing is
    (the common path: gain left at K, no torque as ctrl and bias 0). Every actuator's force
    law and force range agree, for joints inside the backlash, saturated and unsaturated."""
    from contracts.ids import RobotId, TeamColor
    from simulator.world import RobotPlacement, World

    rng = np.random.default_rng(3)
    robots = [
        RobotPlacement(id=RobotId(team, 1), model="kid-default", x_m=x, y_m=0.0, yaw_rad=0.0)
        for team, x in ((TeamColor.RED, -1.0), (TeamColor.BLUE, 1.0))
    ]
    worlds = [World.create(field_class="kid", robots=robots, seed=0) for _ in range(2)]
    common, general = worlds
    ids = common.motors._ids
    n = len(common.motors.params.gain)
    qpos = common.data.qpos[common.motors._qpos] + rng.normal(0.0, 0.05, n)
    qvel = rng.normal(0.0, 3.0, n)
    targets = qpos + rng.normal(0.0, 0.02, n) * (rng.random(n) < 0.6)  # 40 % in the play
    laws = []
    for world in worlds:
        world.data.qpos[world.motors._qpos] = qpos
        world.data.qvel[world.motors._dof] = qvel
        world.motors.set_positions(ids, targets)
    general.motors.set_held(np.array([0]), targets[:1])
    for world in worlds:
        world.motors.apply(world.data)
        m, u = world.model, world.data.ctrl[ids]
        laws.append(
            np.stack([
                m.actuator_gainprm[ids, 0] * u + m.actuator_biasprm[ids, 1] * qpos
                + m.actuator_biasprm[ids, 2] * qvel,
                m.actuator_forcerange[ids, 0],
                m.actuator_forcerange[ids, 1],
            ])
        )  # fmt: skip
    assert not common.motors._any_held and general.motors._any_held
    np.testing.assert_allclose(laws[0], laws[1], rtol=0, atol=1e-12)
    force = laws[0][0]
    assert (force == 0.0).sum() >= 0.2 * n  # inside the play: no torque
    assert (np.abs(force) > 0).sum() >= 0.2 * n
