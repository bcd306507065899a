"""Device names come from the model: a manifest names its motors, position sensors, IMUs, camera
and force sensors as its team's robot file does; bad and doubled names are problems naming the
file, the pointer and what was expected; ``hlvs check`` lists what the robot answers to; the
built-in models keep the league's sample robot's names."""

from __future__ import annotations

import io
import json
from pathlib import Path
from typing import Any

import pytest

from contracts.ids import RobotId, TeamColor
from hlvs.commands.check import check_file, check_report
from simulator.errors import ModelError
from simulator.world import ADULT_DEFAULT, KID_DEFAULT, MOTOR_NAMES, RobotPlacement, World
from simulator.world.robots.team import load_team_model
from simulator.world.types import DeviceKind
from tests.unit.models.conftest import box_robot, edit_manifest

RED1 = RobotId(TeamColor.RED, 1)


def _motors(folder: Path, names: dict[str, dict[str, Any]]) -> list[dict[str, Any]]:
    manifest = json.loads((folder / "robot_model.json").read_text())
    motors: list[dict[str, Any]] = manifest["motors"]
    for motor in motors:
        motor.update(names.get(motor["joint"], {}))
    return motors


def _problems(folder: Path) -> list[str]:
    with pytest.raises(ModelError) as caught:
        load_team_model(folder)
    return [str(p) for p in caught.value.problems]


def test_built_in_models_answer_to_the_league_sample_robots_names() -> None:
    expected = {
        **dict.fromkeys(MOTOR_NAMES, DeviceKind.MOTOR),
        **{f"{m}S": DeviceKind.POSITION_SENSOR for m in MOTOR_NAMES},
        "Accelerometer": DeviceKind.ACCELEROMETER,
        "Gyro": DeviceKind.GYRO,
        "Camera": DeviceKind.CAMERA,
        **dict.fromkeys(("llb", "llf", "lrf", "lrb", "rlb", "rlf", "rrf", "rrb"), DeviceKind.FORCE),
    }
    assert KID_DEFAULT.devices.kinds() == expected
    assert ADULT_DEFAULT.devices.kinds() == expected
    assert "NeckS" in expected and len(expected) == 20 + 20 + 3 + 8


def test_the_manifest_names_every_device_and_the_world_answers_to_them(tmp_path: Path) -> None:
    folder = box_robot(tmp_path / "named", height_m=0.7)
    edit_manifest(
        folder,
        motors=_motors(
            folder,
            {"neck": {"name": "HeadPan [head]", "sensor": "head pan encoder"},
             "hip_l": {"name": 'hip "L" & <left>'}},
        ),  # fmt: skip
        sensor_suffix="_sensor",
        imu=[
            {"link": "imu", "accelerometer": "imu accelerometer", "gyro": "imu gyro"},
            {"link": "head", "accelerometer": "imu_head accelerometer", "gyro": "imu_head gyro"},
        ],
        cameras=[{"name": "camera", "link": "cam", "width": 64, "height": 48, "fov_rad": 1.0}],
        # the simulator's own sensor names are free for a team's devices
        force_sensors={"Accelerometer": "foot_l", "com_velocity": "foot_r"},
    )
    devices = load_team_model(folder).devices.kinds()
    assert devices == {
        'hip "L" & <left>': DeviceKind.MOTOR,
        "hip_r": DeviceKind.MOTOR,
        "arm_l": DeviceKind.MOTOR,
        "arm_r": DeviceKind.MOTOR,
        "HeadPan [head]": DeviceKind.MOTOR,
        'hip "L" & <left>_sensor': DeviceKind.POSITION_SENSOR,
        "hip_r_sensor": DeviceKind.POSITION_SENSOR,
        "arm_l_sensor": DeviceKind.POSITION_SENSOR,
        "arm_r_sensor": DeviceKind.POSITION_SENSOR,
        "head pan encoder": DeviceKind.POSITION_SENSOR,
        "imu accelerometer": DeviceKind.ACCELEROMETER,
        "imu_head accelerometer": DeviceKind.ACCELEROMETER,
        "imu gyro": DeviceKind.GYRO,
        "imu_head gyro": DeviceKind.GYRO,
        "camera": DeviceKind.CAMERA,
        "Accelerometer": DeviceKind.FORCE,
        "com_velocity": DeviceKind.FORCE,
    }
    world = World.create(
        field_class="kid",
        robots=[RobotPlacement(id=RED1, model=str(folder), x_m=0.0, y_m=0.0, yaw_rad=0.0)],
        seed=1,
    )
    assert world.devices(RED1) == devices
    world.set_motor_position(RED1, "HeadPan [head]", 0.4)
    world.set_motor_position(RED1, 'hip "L" & <left>', -0.4)
    for _ in range(30):
        world.step()
    names = ["head pan encoder", 'hip "L" & <left>_sensor', "imu accelerometer",
             "imu_head accelerometer", "imu gyro", "imu_head gyro", "Accelerometer"]  # fmt: skip
    values = world.read_sensors(RED1, names)
    assert len(values) == 2 + 4 * 3 + 1
    assert values[0] > 0.01 and values[1] < -0.01  # each joint turned as its motor was told
    assert world.read_position(RED1, "head pan encoder") == values[0]
    assert world.read_positions(RED1)["head pan encoder"] == values[0]
    assert world.read_position_array(RED1)[4] == values[0]
    body_imu, head_imu = values[2:5], values[5:8]
    assert sum(v * v for v in body_imu) ** 0.5 == pytest.approx(9.81, abs=2.0)
    assert tuple(body_imu) == world.read_accelerometer(RED1)  # the first IMU is "the" IMU
    # the second IMU sits in its own link and reads its own sensor
    model = world.model
    site = model.site("red_1/site:imu1")
    assert model.body(int(site.bodyid[0])).name == "red_1/link:head"
    adr = int(model.sensor("red_1/imu1:Accelerometer").adr[0])
    assert list(head_imu) == world.data.sensordata[adr : adr + 3].tolist()
    assert values[-1] >= 0.0 and values[-1] == world.read_force(RED1, "Accelerometer")


def test_bad_and_doubled_names_are_problems_naming_the_pointer(tmp_path: Path) -> None:
    folder = box_robot(tmp_path / "bad", height_m=0.7)
    edit_manifest(
        folder,
        motors=_motors(folder, {"hip_r": {"name": "root"}, "arm_l": {"name": "arm\nleft"}}),
        imu={"link": "imu", "accelerometer": "Gyro"},
        cameras=[{"name": "Camera ", "link": "cam", "width": 64, "height": 48, "fov_rad": 1.0}],
        force_sensors={"neckS": "foot_l", "x" * 101: "foot_r"},
    )
    manifest = str(folder.resolve() / "robot_model.json")
    expected = "expected 1 to 100 printable characters, no space at either end"
    assert _problems(folder) == [
        f"{manifest}: /motors/1/name: 'root' is the simulator's name of the robot's free base; "
        "expected another motor name",
        f"{manifest}: /motors/2/name: 'arm\\nleft' holds the unprintable character '\\n'; "
        f"{expected}",
        f"{manifest}: /motors/2/name: 'arm\\nleftS' holds the unprintable character '\\n'; "
        f"{expected}",
        f"{manifest}: /imu/gyro: 'Gyro' (a gyro) is also the name of /imu/accelerometer "
        "(an accelerometer); expected a name no other device of the robot has",
        f"{manifest}: /cameras/0/name: 'Camera ' has a space at one end; {expected}",
        f"{manifest}: /force_sensors/neckS: 'neckS' (a force sensor) is also the name of "
        "/motors/4/name (a position sensor (name + sensor_suffix)); expected a name no other "
        "device of the robot has",
        f"{manifest}: /force_sensors/{'x' * 101}: a device name of 101 characters; {expected}",
    ]


def test_sensor_suffix_must_tell_sensors_from_motors(tmp_path: Path) -> None:
    folder = box_robot(tmp_path / "suffix", height_m=0.7)
    edit_manifest(folder, sensor_suffix="")
    manifest = str(folder.resolve() / "robot_model.json")
    assert _problems(folder) == [
        f"{manifest}: /sensor_suffix: an empty suffix gives each position sensor its motor's "
        "name; expected a suffix (the league's robots use S or _sensor) or a sensor name in "
        "every motor"
    ]
    joints = ("hip_l", "hip_r", "arm_l", "arm_r", "neck")
    named = box_robot(tmp_path / "named", height_m=0.7)  # (models are cached per folder)
    edit_manifest(
        named,
        sensor_suffix="",
        motors=_motors(named, {j: {"sensor": f"{j} encoder"} for j in joints}),
    )
    names = load_team_model(named).devices.position_sensors
    assert names == tuple(f"{j} encoder" for j in joints)
    wrong = box_robot(tmp_path / "wrong", height_m=0.7)
    edit_manifest(wrong, sensor_suffix=7)
    manifest = str(wrong.resolve() / "robot_model.json")
    assert _problems(wrong) == [f"{manifest}: /sensor_suffix: 7 is not a string"]


def test_a_second_imu_names_its_devices(tmp_path: Path) -> None:
    folder = box_robot(tmp_path / "imus", height_m=0.7)
    edit_manifest(folder, imu=[{"link": "imu", "acelerometer": "a"}, {"link": "head"}])
    manifest = str(folder.resolve() / "robot_model.json")
    assert _problems(folder) == [
        f"{manifest}: /imu/0/acelerometer: unknown field; known fields: accelerometer, gyro, link",
        f"{manifest}: /imu/1/accelerometer: missing; expected a string",
        f"{manifest}: /imu/1/gyro: missing; expected a string",
    ]
    empty = box_robot(tmp_path / "empty", height_m=0.7)
    edit_manifest(empty, imu=[])
    manifest = str(empty.resolve() / "robot_model.json")
    assert _problems(empty) == [f"{manifest}: /imu: an empty array; expected at least one IMU"]


def test_hlvs_check_lists_the_devices_and_warns_of_a_camera_not_served(tmp_path: Path) -> None:
    folder = box_robot(tmp_path / "listed", height_m=0.7)
    camera = {"link": "cam", "width": 64, "height": 48, "fov_rad": 1.0}
    edit_manifest(
        folder,
        sensor_suffix="_sensor",
        imu=[{"link": "imu"}, {"link": "head", "accelerometer": "head acc", "gyro": "head gyro"}],
        cameras=[{"name": "left", **camera}, {"name": "right", **camera}],
        force_sensors={"llb": "foot_l"},
    )
    out = io.StringIO()
    assert check_file(folder, out=out) == 0
    lines = out.getvalue().splitlines()
    assert lines[1:7] == [
        '  motors (5): "hip_l", "hip_r", "arm_l", "arm_r", "neck"',
        '  position sensors (5): "hip_l_sensor", "hip_r_sensor", "arm_l_sensor", '
        '"arm_r_sensor", "neck_sensor"',
        '  accelerometers (2): "Accelerometer", "head acc"',
        '  gyros (2): "Gyro", "head gyro"',
        '  camera (1): "left"',
        '  force sensors (1): "llb"',
    ]
    manifest = str(folder.resolve() / "robot_model.json")
    assert (
        f"warning: {manifest}: /cameras/1: camera 'right' is not served: the robot API renders "
        "one camera per robot ('left', /cameras/0); it still counts for the rule book"
    ) in lines
    record = check_report(folder).as_json()
    assert record["devices"]["gyro"] == ["Gyro", "head gyro"]
    assert record["devices"]["position_sensor"][-1] == "neck_sensor"
    assert list(record)[:2] == ["measurements", "devices"]
