"""Device access of the robot API and the referee's world commands."""

from __future__ import annotations

import math

import pytest

from contracts.geometry import Pose
from contracts.ids import RobotId, TeamColor
from referee.snapshot import BodyPart, PlaceBall, RemoveRobot, RestoreRobot, SetLimp, TeleportRobot
from simulator.errors import UnknownDeviceError
from simulator.world import FORCE_SENSORS, MOTOR_NAMES, CameraRenderer, DeviceKind, World
from tests.unit.world.conftest import RED_1, run_steps


def test_every_contract_device_exists(one_robot_world: World) -> None:
    devices = one_robot_world.devices(RED_1)
    for motor in MOTOR_NAMES:
        assert devices[motor] is DeviceKind.MOTOR
        assert devices[f"{motor}S"] is DeviceKind.POSITION_SENSOR
    assert devices["Accelerometer"] is DeviceKind.ACCELEROMETER
    assert devices["Gyro"] is DeviceKind.GYRO
    assert devices["Camera"] is DeviceKind.CAMERA
    for name in FORCE_SENSORS:
        assert devices[name] is DeviceKind.FORCE
    assert len(devices) == 20 + 20 + 3 + 8
    assert one_robot_world.camera_info(RED_1) == (320, 240, pytest.approx(1.04))
    fovy = math.radians(float(one_robot_world.model.camera("red_1/Camera").fovy[0]))
    assert 2 * math.atan(math.tan(fovy / 2) * 320 / 240) == pytest.approx(1.04, abs=1e-4)


def test_standing_robot_sensors_read_like_a_real_imu(one_robot_world: World) -> None:
    world = one_robot_world
    run_steps(world, 50)
    ax, ay, az = world.read_accelerometer(RED_1)
    assert az == pytest.approx(9.81, abs=0.2) and abs(ax) < 0.2 and abs(ay) < 0.2
    assert all(abs(v) < 0.05 for v in world.read_gyro(RED_1))
    total = sum(world.read_force(RED_1, name) for name in FORCE_SENSORS)
    weight = float(world.model.body("red_1/torso").subtreemass[0]) * 9.81
    assert total == pytest.approx(weight, rel=0.05)
    assert all(world.read_force(RED_1, name) > 0.5 for name in FORCE_SENSORS)
    positions = world.read_positions(RED_1)
    assert set(positions) == {f"{m}S" for m in MOTOR_NAMES}
    with pytest.raises(UnknownDeviceError) as caught:
        world.read_force(RED_1, "Bumper")
    assert caught.value.name == "Bumper"


def test_motor_position_velocity_torque_and_pid(one_robot_world: World) -> None:
    world = one_robot_world
    world.set_motor_position(RED_1, "Neck", 1.0)
    world.set_motor_velocity(RED_1, "Neck", 1.0)  # rad/s: needs about a second
    run_steps(world, 25)
    assert 0.1 < world.read_position(RED_1, "NeckS") < 0.4
    run_steps(world, 150)
    assert world.read_position(RED_1, "NeckS") == pytest.approx(1.0, abs=0.03)
    world.set_motor_position(RED_1, "Neck", 9.0)  # clamped to the joint range
    run_steps(world, 200)
    assert world.read_position(RED_1, "NeckS") == pytest.approx(2.0, abs=0.05)
    world.set_motor_torque(RED_1, "ShoulderL", 2.0)  # swings the arm forward and up
    run_steps(world, 100)
    assert world.read_position(RED_1, "ShoulderLS") > 1.0
    world.set_motor_position(RED_1, "ShoulderL", 0.0)  # back to position control
    world.set_motor_pid(RED_1, "ShoulderL", 10.0, 0.0, 0.0)
    run_steps(world, 150)
    assert world.read_position(RED_1, "ShoulderLS") == pytest.approx(0.0, abs=0.05)
    with pytest.raises(UnknownDeviceError):
        world.set_motor_position(RED_1, "PelvL[hip]", 0.1)


def test_limp_robot_ignores_motors_until_restored(one_robot_world: World) -> None:
    world = one_robot_world
    world.apply(SetLimp(robot=RED_1, limp=True))
    assert world.is_limp(RED_1)
    world.set_motor_position(RED_1, "Neck", 1.0)
    world.set_motor_position(RED_1, "ShoulderL", 1.5)
    run_steps(world, 125)
    snap = world.snapshot().robots[0]
    assert snap.limp
    assert abs(world.read_position(RED_1, "NeckS")) < 0.05  # no actuation while limp
    assert abs(world.read_position(RED_1, "ShoulderLS")) < 0.05
    world.apply(SetLimp(robot=RED_1, limp=False))  # the last commands apply again
    run_steps(world, 125)
    assert world.read_position(RED_1, "NeckS") == pytest.approx(1.0, abs=0.05)
    world.apply(TeleportRobot(robot=RED_1, pose=Pose(x_m=2.0, y_m=-1.0, yaw_rad=-1.0)))
    run_steps(world, 250)
    snap = world.snapshot().robots[0]
    assert not snap.limp and not snap.fallen
    assert snap.position[:2] == pytest.approx((2.0, -1.0), abs=0.02)
    assert snap.yaw_rad == pytest.approx(-1.0, abs=0.02)
    assert world.read_position(RED_1, "NeckS") == pytest.approx(0.0, abs=0.05)  # standing


def test_remove_and_restore(one_robot_world: World) -> None:
    world = one_robot_world
    world.apply(RemoveRobot(robot=RED_1))
    run_steps(world, 100)
    snap = world.snapshot().robots[0]
    assert world.is_removed(RED_1) and snap.removed
    assert snap.position[:2] == pytest.approx((50.0, 11.0))  # parked, frozen
    assert snap.ground_contacts == frozenset()
    world.apply(RestoreRobot(robot=RED_1, pose=Pose(x_m=-3.0, y_m=2.0, yaw_rad=0.0)))
    run_steps(world, 125)
    snap = world.snapshot().robots[0]
    assert not snap.removed and not snap.fallen
    assert snap.position[:2] == pytest.approx((-3.0, 2.0), abs=0.02)


def test_place_ball_with_velocity_and_last_toucher() -> None:
    from simulator.world import RobotPlacement

    blue = RobotId(TeamColor.BLUE, 3)
    robot = RobotPlacement(id=blue, model="kid-default", x_m=1.0, y_m=0.0, yaw_rad=math.pi)
    world = World.create(field_class="kid", robots=[robot], seed=1)
    world.apply(PlaceBall(position=(-1.0, 0.0, 0.07), velocity=(3.0, 0.0, 0.0)))
    snap = world.snapshot()
    assert snap.ball.position == pytest.approx((-1.0, 0.0, 0.07))
    assert snap.ball.velocity == pytest.approx((3.0, 0.0, 0.0))
    assert snap.last_ball_toucher is None
    touched = None
    for _ in range(200):
        world.step()
        snap = world.snapshot()
        if snap.robots[0].ball_contacts:
            touched = snap.robots[0].ball_contacts
            break
    assert touched and all(isinstance(part, BodyPart) for part in touched)
    assert snap.last_ball_toucher == blue
    assert snap.last_ball_touch_ms == world.sim_time_ms


def test_head_camera_renders_bgr(one_robot_world: World) -> None:
    world = one_robot_world
    with CameraRenderer(world, 320, 240) as camera:
        image = camera.render(RED_1)
    assert len(image) == 320 * 240 * 3
    pixels = memoryview(image)
    # looking over a green field: green dominates blue and red in the lower half (B,G,R order)
    lower = bytes(pixels[320 * 3 * 180 : 320 * 3 * 181])
    b, g, r = (sum(lower[i::3]) for i in range(3))
    assert g > r and g > b
