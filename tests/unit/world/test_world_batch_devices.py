"""Batch device access (what the robot API uses each step) matches the one-by-one calls."""

from __future__ import annotations

import math

import numpy as np
import pytest

from simulator.errors import UnknownDeviceError
from simulator.world import FORCE_SENSORS, MOTOR_NAMES, RobotPlacement, World
from simulator.world.camera import ROBOT_CAMERA_QUALITY, robot_camera_model
from tests.unit.world.conftest import RED_1, run_steps


def _world() -> World:
    placement = RobotPlacement(id=RED_1, model="kid-default", x_m=-1.0, y_m=0.5, yaw_rad=0.3)
    return World.create(field_class="kid", robots=[placement], seed=7)


def test_set_motor_positions_equals_single_calls() -> None:
    one, batch = _world(), _world()
    names = list(MOTOR_NAMES)
    values = [0.3 * math.sin(i) for i in range(len(names))]
    values[3] = 10.0  # clamped to the joint range
    values[5] = float("nan")  # ignored
    one.set_motor_torque(RED_1, names[0], 0.5)  # a position command leaves torque mode
    batch.set_motor_torque(RED_1, names[0], 0.5)
    for name, value in zip(names, values, strict=True):
        one.set_motor_position(RED_1, name, value)
    batch.set_motor_positions(RED_1, names, values)
    assert np.array_equal(one.motors.target, batch.motors.target)
    assert not batch.motors.torque_mode.any()
    run_steps(one, 20)
    run_steps(batch, 20)
    assert np.array_equal(one.data.qpos, batch.data.qpos)


def test_set_motor_positions_keeps_the_last_value_of_a_repeated_name() -> None:
    world = _world()
    world.set_motor_positions(RED_1, ["Neck", "Head", "Neck"], [0.1, 0.2, -0.3])
    actuators = world.index.by_id[RED_1].actuators
    assert world.motors.target[actuators[0]] == pytest.approx(-0.3)
    assert world.motors.target[actuators[1]] == pytest.approx(0.2)
    with pytest.raises(UnknownDeviceError):
        world.set_motor_positions(RED_1, ["Tail"], [0.0])
    with pytest.raises(ValueError, match="2 motor names for 1 positions"):
        world.set_motor_positions(RED_1, ["Neck", "Head"], [0.0])


def test_read_sensors_equals_single_reads() -> None:
    world = _world()
    world.set_motor_positions(RED_1, list(MOTOR_NAMES), [0.1] * len(MOTOR_NAMES))
    run_steps(world, 30)
    force = FORCE_SENSORS[0]
    names = ["Accelerometer", force, "Gyro"] + [f"{m}S" for m in MOTOR_NAMES]
    expected = [
        *world.read_accelerometer(RED_1),
        world.read_force(RED_1, force),
        *world.read_gyro(RED_1),
        *(world.read_position(RED_1, f"{m}S") for m in MOTOR_NAMES),
    ]
    assert world.read_sensors(RED_1, names).tolist() == expected
    run_steps(world, 1)  # cached plans read the current state
    assert world.read_sensors(RED_1, ["NeckS"])[0] == world.read_position(RED_1, "NeckS")
    with pytest.raises(UnknownDeviceError):
        world.read_sensors(RED_1, ["NoSuchS"])


def test_robot_camera_model_is_a_cheaper_copy() -> None:
    world = _world()
    before = world.model.vis.quality.numslices
    cheap = robot_camera_model(world.model)
    quality = cheap.vis.quality
    assert (quality.numslices, quality.numstacks, quality.numquads) == ROBOT_CAMERA_QUALITY
    assert world.model.vis.quality.numslices == before != ROBOT_CAMERA_QUALITY[0]
    assert (cheap.nq, cheap.ngeom) == (world.model.nq, world.model.ngeom)
