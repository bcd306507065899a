"""Index arrays into MuJoCo's flat state, computed once per model so that stepping, snapshots and
device access are numpy gathers instead of name lookups."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import mujoco
import numpy as np
import numpy.typing as npt

from contracts import RobotId
from referee import BodyPart
from simulator.world.ball import BALL_GEOM, BALL_JOINT
from simulator.world.robots import AnyRobotModel, robot_model
from simulator.world.robots.devices import DeviceNames, imu_sensor
from simulator.world.types import DeviceKind, RobotPlacement, robot_prefix

IntArray = npt.NDArray[np.int64]
PARTS: tuple[BodyPart, ...] = tuple(BodyPart)
PART_BIT = {part: 1 << i for i, part in enumerate(PARTS)}
FOOT_BIT = PART_BIT[BodyPart.FOOT]
HULL_BODIES = ("hand_L", "hand_R", "foot_L", "foot_R")
SOLE_BAND_M = 0.01  # a foot's solids whose bottom is this close to its lowest touch the ground
# what a robot geom can touch, for contact classification (0: anything else)
KIND_TURF, KIND_BALL, KIND_ROBOT = 1, 2, 3
KINDS = 4
PART_SLOTS = 8  # parts padded to one byte, so packbits turns a row of flags into part bits


@dataclass(frozen=True, slots=True)
class RobotIndex:
    """Where one robot lives in the model."""

    id: RobotId
    number: int  # position in World.robot_ids
    prefix: str
    model: AnyRobotModel
    root_qpos: int  # 7 values: x y z qw qx qy qz
    root_dof: int  # 6 values
    motor_qpos: IntArray  # in model.motor_names order
    motor_dof: IntArray
    actuators: IntArray
    motor_slot: dict[str, int]  # motor name -> position in the arrays above
    torso_body: int
    hull_bodies: IntArray
    geoms: IntArray
    accelerometer: int  # sensordata address (3 values) of the first IMU's
    gyro: int
    com_velocity: int
    forces: dict[str, int]  # force sensor's device name -> sensordata address
    camera: int
    qpos_range: tuple[int, int]
    dof_range: tuple[int, int]
    devices: DeviceNames  # the names the robot answers to on the robot API
    position_slot: dict[str, int]  # position sensor's device name -> slot (as motor_slot)
    imus: tuple[tuple[int, int], ...]  # sensordata addresses (accelerometer, gyro) per IMU
    imu_sensors: dict[str, int]  # accelerometer's or gyro's device name -> address (3 values)
    sole_outline: tuple[float, float, float, float]  # RobotState.sole_outline


@dataclass(frozen=True, slots=True)
class WorldIndex:
    robots: tuple[RobotIndex, ...]
    by_id: dict[RobotId, RobotIndex]
    geom_robot: IntArray  # geom -> robot number or -1
    geom_part_bit: IntArray  # geom -> PART_BIT or 0
    geom_part_index: IntArray  # geom -> position in PARTS (0 for non-robot geoms)
    geom_kind: IntArray  # geom -> KIND_TURF / KIND_BALL / KIND_ROBOT or 0
    geom_code: IntArray  # robot geom -> robot * KINDS * PART_SLOTS + part index; others -1
    geom_kind_code: IntArray  # geom -> kind * PART_SLOTS
    dof_robot: IntArray  # dof -> robot number or -1
    turf_geom: int
    ball_geom: int
    ball_qpos: int
    ball_dof: int
    root_xyz: IntArray  # (n, 3) qpos indices
    root_quat: IntArray  # (n, 4)
    torso_bodies: IntArray
    hull_bodies: IntArray  # (n, 4)
    com_velocity: IntArray  # (n, 3) sensordata indices
    actuator_robot: IntArray  # actuator -> robot number
    ball_touch: IntArray  # (n,) sensordata index: contacts of robot n with the ball


def _robot_index(
    model: mujoco.MjModel, number: int, placement: RobotPlacement, geom_names: Sequence[str]
) -> RobotIndex:
    prefix = robot_prefix(placement.id)
    spec = robot_model(placement.model)
    names = spec.motor_names
    joints = [model.joint(f"{prefix}/{name}") for name in names]
    root = model.joint(f"{prefix}/root")
    torso = model.body(f"{prefix}/torso").id
    last_body = torso
    while last_body + 1 < model.nbody and model.body(last_body + 1).name.startswith(prefix + "/"):
        last_body += 1

    def sensor(name: str) -> int:
        return int(model.sensor(f"{prefix}/{name}").adr[0])

    geoms = [i for i, g in enumerate(geom_names) if g.startswith(prefix + "/")]
    devices = spec.devices
    imus = tuple(
        (sensor(imu_sensor(k, DeviceKind.ACCELEROMETER)), sensor(imu_sensor(k, DeviceKind.GYRO)))
        for k in range(len(devices.imus))
    )
    imu_sensors: dict[str, int] = {}
    for imu, (accelerometer, gyro) in zip(devices.imus, imus, strict=True):
        imu_sensors[imu.accelerometer] = accelerometer
        imu_sensors[imu.gyro] = gyro
    qpos_start = int(root.qposadr[0])
    dof_start = int(root.dofadr[0])
    return RobotIndex(
        id=placement.id,
        number=number,
        prefix=prefix,
        model=spec,
        root_qpos=qpos_start,
        root_dof=dof_start,
        motor_qpos=np.array([int(j.qposadr[0]) for j in joints], dtype=np.int64),
        motor_dof=np.array([int(j.dofadr[0]) for j in joints], dtype=np.int64),
        actuators=np.array([model.actuator(f"{prefix}/{n}").id for n in names], dtype=np.int64),
        motor_slot={name: i for i, name in enumerate(names)},
        torso_body=torso,
        hull_bodies=np.array([model.body(f"{prefix}/{b}").id for b in HULL_BODIES], dtype=np.int64),
        geoms=np.array(geoms, dtype=np.int64),
        accelerometer=imus[0][0],
        gyro=imus[0][1],
        com_velocity=sensor("com_velocity"),
        forces={
            name: sensor(mjcf)
            for name, mjcf in zip(devices.forces, devices.force_mjcf, strict=True)
        },
        camera=model.camera(f"{prefix}/{spec.camera.name}").id,
        qpos_range=(qpos_start, qpos_start + 7 + len(names)),
        dof_range=(dof_start, dof_start + 6 + len(names)),
        devices=devices,
        position_slot={name: i for i, name in enumerate(devices.position_sensors)},
        imus=imus,
        imu_sensors=imu_sensors,
        sole_outline=sole_outline(model, model.body(f"{prefix}/{HULL_BODIES[2]}").id),
    )


def sole_outline(model: mujoco.MjModel, foot_body: int) -> tuple[float, float, float, float]:
    """The rectangle (x back, x front, y right, y left) the colliding solids of ``foot_body``
    that reach the ground cover in its frame (those whose bottom is within :data:`SOLE_BAND_M`
    of the lowest): each geom's bounding box (``geom_aabb``) turned into the body's frame.
    The league reads the feet's contact points with the ground (hlvs_webots referee.py:
    686-770), where Webots puts them at the corners of its robots' foot boxes."""
    boxes = []
    turn = np.zeros(9)
    for geom in range(model.ngeom):
        if model.geom_bodyid[geom] != foot_body:
            continue
        if not (model.geom_contype[geom] or model.geom_conaffinity[geom]):
            continue
        mujoco.mju_quat2Mat(turn, model.geom_quat[geom])
        r = turn.reshape(3, 3)
        centre = model.geom_pos[geom] + r @ model.geom_aabb[geom, :3]
        half = np.abs(r) @ model.geom_aabb[geom, 3:]
        boxes.append((centre - half, centre + half))
    if not boxes:
        return (0.0, 0.0, 0.0, 0.0)
    bottom = min(lo[2] for lo, _ in boxes)
    sole = [(lo, hi) for lo, hi in boxes if lo[2] <= bottom + SOLE_BAND_M]
    return (
        float(min(lo[0] for lo, _ in sole)),
        float(max(hi[0] for _, hi in sole)),
        float(min(lo[1] for lo, _ in sole)),
        float(max(hi[1] for _, hi in sole)),
    )


def _table(starts: Sequence[int], width: int) -> IntArray:
    """(n, width) array of consecutive indices starting at each of ``starts``."""
    return (np.asarray(starts, dtype=np.int64).reshape(-1, 1) + np.arange(width)).astype(np.int64)


def build_index(model: mujoco.MjModel, placements: Sequence[RobotPlacement]) -> WorldIndex:
    geom_names = [model.geom(i).name for i in range(model.ngeom)]
    robots = tuple(_robot_index(model, n, p, geom_names) for n, p in enumerate(placements))
    geom_robot = np.full(model.ngeom, -1, dtype=np.int64)
    geom_part = np.zeros(model.ngeom, dtype=np.int64)
    part_by_value = {part.value: part for part in PARTS}
    for robot in robots:
        for g in robot.geoms:
            part = geom_names[g][len(robot.prefix) + 1 :].split(":", 1)[0]
            if part in part_by_value:
                geom_robot[g] = robot.number
                geom_part[g] = PART_BIT[part_by_value[part]]
    dof_robot = np.full(model.nv, -1, dtype=np.int64)
    actuator_robot = np.full(model.nu, -1, dtype=np.int64)
    for robot in robots:
        dof_robot[robot.dof_range[0] : robot.dof_range[1]] = robot.number
        actuator_robot[robot.actuators] = robot.number
    ball_joint = model.joint(BALL_JOINT)
    geom_kind = np.where(geom_robot >= 0, KIND_ROBOT, 0).astype(np.int64)
    geom_kind[model.geom("turf").id] = KIND_TURF
    geom_kind[model.geom(BALL_GEOM).id] = KIND_BALL
    part_index = np.array([max(int(b).bit_length() - 1, 0) for b in geom_part], dtype=np.int64)
    geom_code = np.where(geom_robot >= 0, geom_robot * KINDS * PART_SLOTS + part_index, -1)
    return WorldIndex(
        robots=robots,
        by_id={r.id: r for r in robots},
        geom_robot=geom_robot,
        geom_part_bit=geom_part,
        geom_kind=geom_kind,
        geom_code=geom_code,
        geom_kind_code=geom_kind * PART_SLOTS,
        geom_part_index=part_index,
        dof_robot=dof_robot,
        turf_geom=model.geom("turf").id,
        ball_geom=model.geom(BALL_GEOM).id,
        ball_qpos=int(ball_joint.qposadr[0]),
        ball_dof=int(ball_joint.dofadr[0]),
        root_xyz=_table([r.root_qpos for r in robots], 3),
        root_quat=_table([r.root_qpos + 3 for r in robots], 4),
        torso_bodies=np.array([r.torso_body for r in robots], dtype=np.int64),
        hull_bodies=np.array([r.hull_bodies for r in robots], dtype=np.int64).reshape(-1, 4),
        com_velocity=_table([r.com_velocity for r in robots], 3),
        actuator_robot=actuator_robot,
        ball_touch=np.array(
            [int(model.sensor(f"{r.prefix}/ball_touch").adr[0]) for r in robots], dtype=np.int64
        ),
    )
