"""A team robot model (the Wolfgang package) served over the robot API exactly as the built-in:
its own device names, the HLVS warnings for names it does not have, the same measurements; and
named as its team's robot file names it, every device bit-bots' own bridge asks for."""

from __future__ import annotations

import json
import math
import shutil
import time
from pathlib import Path

import pytest

from contracts.ids import RobotId, TeamColor
from contracts.robot_api import messages_pb2 as pb
from robot.client import RobotClient
from simulator.api.world_cameras import world_render_worker
from simulator.world import RobotPlacement, World
from tests.integration.api.harness import RED1, running_server

WOLFGANG = Path(__file__).resolve().parents[3] / "configs" / "examples" / "robots" / "wolfgang"
BLUE1 = RobotId(TeamColor.BLUE, 1)


def test_client_enables_sensors_and_moves_the_head_by_hlvs_names() -> None:
    world = World.create(
        field_class="kid",
        robots=[
            RobotPlacement(id=RED1, model=str(WOLFGANG), x_m=-1.0, y_m=0.0, yaw_rad=0.0),
            RobotPlacement(id=BLUE1, model="kid-default", x_m=1.0, y_m=0.0, yaw_rad=math.pi),
        ],
        seed=3,
    )
    worker = world_render_worker(world)
    with running_server(robots=(RED1, BLUE1), world=world, worker=worker) as (_d, ports):
        client = RobotClient("127.0.0.1", ports[RED1], retries=3, retry_interval_s=0.1)
        with client.connect() as robot:
            robot.enable_many(
                {"HeadPanS": 8, "HeadTiltS": 8, "Accelerometer": 8, "Gyro": 8, "llb": 8,
                 "Camera": 32, "NeckS": 8}
            )
            warnings: list[str] = []
            for _ in range(80):
                msg = robot.receive(timeout=10)
                warnings += [m.text for m in msg.messages]
                robot.set_positions({"HeadPan": 0.5, "HeadTilt": -0.3, "Neck": 1.0})
            # the catalogue's servo takes a fraction of a second to settle; the free-running
            # world may be ahead of the client's reading by the messages in flight
            deadline = time.monotonic() + 10.0
            while True:
                last = robot.receive(timeout=10)
                sensors = {s.name: s.value for s in last.position_sensors}
                settled = abs(sensors.get("HeadPanS", 0.0) - 0.5) < 0.05
                if (last.cameras and settled) or time.monotonic() > deadline:
                    break
    assert set(sensors) == {"HeadPanS", "HeadTiltS"}
    assert sensors["HeadPanS"] == pytest.approx(0.5, abs=0.05)
    assert sensors["HeadTiltS"] == pytest.approx(-0.3, abs=0.05)
    assert 8.0 < last.accelerometers[0].value.Z < 11.5  # standing, gravity along the IMU's z
    assert last.gyros and [f.name for f in last.forces] == ["llb"]
    image = last.cameras[0]
    assert (image.name, image.width, image.height) == ("Camera", 320, 240)
    assert len(image.image) == 320 * 240 * 3 and len(set(image.image[::997])) > 3
    # names a Wolfgang does not have get the HLVS warnings, once per request that names them
    assert sum("NeckS" in w for w in warnings) == 1  # enabled once
    neck = [w for w in warnings if '"Neck"' in w]  # a target in each of the 80 requests
    assert 1 < len(neck) <= 80
    assert set(neck) == {'Motor "Neck" not found, position command ignored.'}


# bit-bots' Wolfgang bridge to the league's robot API (bit-bots/wolfgang_robot at 6f5a4d6,
# wolfgang_robocup_api/wolfgang_robocup_api/wolfgang_robocup_api.py): it enables these 33
# sensors (lines 50-69: a position sensor per URDF revolute joint, the foot force sensors, the
# camera and the two IMUs of WolfgangRobocup's Wolfgang.proto) and commands the motors by their
# Webots names (joint_to_webots, lines 469-474).
BRIDGE_JOINTS = (
    "RElbow", "RShoulderRoll", "RShoulderPitch", "LElbow", "LShoulderRoll", "LShoulderPitch",
    "RAnkleRoll", "RAnklePitch", "RKnee", "RHipPitch", "RHipRoll", "RHipYaw", "LAnkleRoll",
    "LAnklePitch", "LKnee", "LHipPitch", "LHipRoll", "LHipYaw", "HeadTilt", "HeadPan",
)  # fmt: skip


def _webots(joint: str) -> str:
    if joint in ("RHipRoll", "LHipRoll"):
        return joint + " [hip]"
    if joint in ("RShoulderPitch", "LShoulderPitch"):
        return joint + " [shoulder]"
    return joint


BRIDGE_FORCES = ("llb", "llf", "lrf", "lrb", "rlb", "rlf", "rrf", "rrb")
BRIDGE_SENSORS = (
    "camera", "imu accelerometer", "imu gyro", "imu_head accelerometer", "imu_head gyro",
    *(_webots(j) + "_sensor" for j in BRIDGE_JOINTS), *BRIDGE_FORCES,
)  # fmt: skip
BRIDGE_MOTORS = tuple(_webots(j) for j in BRIDGE_JOINTS)


def bridge_named_wolfgang(folder: Path) -> Path:
    """The Wolfgang example's model with a manifest naming its devices as Wolfgang.proto does."""
    manifest = json.loads((WOLFGANG / "robot_model.json").read_text())
    for motor in manifest["motors"]:
        motor["name"] = _webots(motor["joint"])
    manifest["standing_pose_rad"] = {
        _webots(k): v for k, v in manifest["standing_pose_rad"].items()
    }
    manifest["sensor_suffix"] = "_sensor"
    manifest["imu"] = [
        {"link": "imu_frame", "accelerometer": "imu accelerometer", "gyro": "imu gyro"},
        {"link": "imu_frame_2", "accelerometer": "imu_head accelerometer",
         "gyro": "imu_head gyro"},
    ]  # fmt: skip
    manifest["cameras"][0]["name"] = "camera"
    # a package of its own: the example's files copied beside the new manifest (a model's
    # files must lie inside its package's folder)
    shutil.copytree(WOLFGANG, folder, dirs_exist_ok=True)
    (folder / "robot_model.json").write_text(json.dumps(manifest))
    return folder


def test_bit_bots_bridge_gets_every_device_it_asks_for_without_a_warning(tmp_path: Path) -> None:
    assert len(BRIDGE_SENSORS) == len(set(BRIDGE_SENSORS)) == 33
    package = bridge_named_wolfgang(tmp_path / "wolfgang_bitbots")
    world = World.create(
        field_class="kid",
        robots=[RobotPlacement(id=RED1, model=str(package), x_m=-1.0, y_m=0.0, yaw_rad=0.0)],
        seed=5,
    )
    worker = world_render_worker(world)
    with running_server(robots=(RED1,), world=world, worker=worker) as (_d, ports):
        client = RobotClient("127.0.0.1", ports[RED1], retries=3, retry_interval_s=0.1)
        with client.connect() as robot:
            first = pb.ActuatorRequests()  # as the bridge's first request: sensors and motors
            for name in BRIDGE_SENSORS:
                first.sensor_time_steps.add(name=name, timeStep=16 if name == "camera" else 8)
            for name in BRIDGE_MOTORS:
                first.motor_pids.add(name=name, PID=pb.Vector3(X=10.0, Y=0.0, Z=0.0))
                first.motor_torques.add(name=name, torque=0.0)
            robot.send(first)
            standing = json.loads((package / "robot_model.json").read_text())["standing_pose_rad"]
            warnings: list[str] = []
            seen: set[str] = set()
            for received in range(1000):  # a second of simulated time, then a camera's step
                msg = robot.receive(timeout=10)
                warnings += [m.text for m in msg.messages]
                step = pb.ActuatorRequests()  # the bridge's every request: positions, velocities
                for name in BRIDGE_MOTORS:
                    step.motor_positions.add(name=name, position=standing.get(name, 0.0))
                    step.motor_velocities.add(name=name, velocity=5.0)
                robot.send(step)
                for group in (msg.position_sensors, msg.accelerometers, msg.gyros, msg.forces,
                              msg.cameras):  # fmt: skip
                    seen.update(device.name for device in group)
                if received >= 125 and msg.cameras:
                    break
            last = msg
    assert warnings == []
    assert sorted(seen) == sorted(BRIDGE_SENSORS)  # each got values, in the same message:
    positions = {s.name: s.value for s in last.position_sensors}
    assert sorted(positions) == sorted(j + "_sensor" for j in BRIDGE_MOTORS)
    assert all(math.isfinite(v) for v in positions.values())
    for accelerometer in last.accelerometers:  # both IMUs upright in a standing robot
        value = accelerometer.value
        assert 8.0 < math.sqrt(value.X**2 + value.Y**2 + value.Z**2) < 11.5
    assert sorted(g.name for g in last.gyros) == ["imu gyro", "imu_head gyro"]
    assert sorted(f.name for f in last.forces) == sorted(BRIDGE_FORCES)
    image = last.cameras[0]
    assert (image.name, image.width, image.height) == ("camera", 320, 240)
    assert len(image.image) == 320 * 240 * 3
