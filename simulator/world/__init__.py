"""The MuJoCo soccer world: field, goals, ball, robots; stepping, snapshots, commands, devices.

Public surface::

    World.create(*, field_class, robots, seed, physics_dt_s=0.002, step_ms=8,
                 divergence_policy="fail", initial_joint_noise_rad=0.0, texture_seed=None,
                 sensor_model=None, camera_model=None) -> World  (ideal sensors and camera)
    World.from_spec(spec: MatchSpec) -> World  (the spec's look and sensors)
    world.look: Look (look_for(texture_seed)); world.sensor_model: SensorModel;
    world.camera_model: CameraModel (SensorModel.ideal() / CameraModel.ideal(): exact values)
    world.step(); world.snapshot() -> WorldSnapshot; world.apply(WorldCommand)
    world.sim_time_ms, world.robot_ids, world.model, world.data, world.field
    world.devices(robot) -> dict[str, DeviceKind]; set_motor_position / velocity / torque / pid;
    set_motor_positions(robot, names, rads) (batch); read_sensors(robot, names) -> ndarray
    (batch, flat); read_position, read_positions, read_position_array, read_accelerometer,
    read_gyro, read_force, camera_info, is_limp, is_removed, motor_names
    CameraRenderer(world, width, height).render(robot, sim_time_ms=0) -> bytes (B,G,R rows top
    to bottom, through the world's camera model)
    known_models() -> tuple[str, ...]; robot_model(name) -> RobotModel
"""

from __future__ import annotations

from simulator.world.camera import CameraRenderer
from simulator.world.camera_model import CameraModel
from simulator.world.look import Look, look_for
from simulator.world.robots import (
    ADULT_DEFAULT,
    FORCE_SENSORS,
    KID_DEFAULT,
    MOTOR_NAMES,
    HumanoidGeometry,
    RobotModel,
    known_models,
    robot_model,
)
from simulator.world.sensor_noise import ImuAxisModel, SensorModel
from simulator.world.types import (
    DeviceKind,
    DivergencePolicy,
    RobotPlacement,
    robot_prefix,
)
from simulator.world.world import World

__all__ = [
    "ADULT_DEFAULT",
    "CameraModel",
    "CameraRenderer",
    "DeviceKind",
    "DivergencePolicy",
    "FORCE_SENSORS",
    "HumanoidGeometry",
    "ImuAxisModel",
    "KID_DEFAULT",
    "known_models",
    "Look",
    "look_for",
    "MOTOR_NAMES",
    "robot_model",
    "robot_prefix",
    "RobotModel",
    "RobotPlacement",
    "SensorModel",
    "World",
]
