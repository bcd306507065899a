"""The MuJoCo soccer world: field, goals, ball, robots; stepping, snapshots, commands, devices.

Public surface::

    World.create(*, field_class, robots, seed, physics_dt_s=0.002, step_ms=8,
                 divergence_policy="fail", initial_joint_noise_rad=0.0) -> World
    World.from_spec(spec: MatchSpec) -> World
    world.step(); world.snapshot() -> WorldSnapshot; world.apply(WorldCommand)
    world.sim_time_ms, world.robot_ids, world.model, world.data, world.field
    world.devices(robot) -> dict[str, DeviceKind]; set_motor_position / velocity / torque / pid;
    set_motor_positions(robot, names, rads) (batch); read_sensors(robot, names) -> ndarray
    (batch, flat); read_position, read_positions, read_position_array, read_accelerometer,
    read_gyro, read_force, camera_info, is_limp, is_removed, motor_names
    CameraRenderer(world, width, height).render(robot) -> bytes (B,G,R rows top to bottom)
    known_models() -> tuple[str, ...]; robot_model(name) -> RobotModel
"""

from __future__ import annotations

from simulator.world.camera import CameraRenderer
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
from simulator.world.types import (
    DeviceKind,
    DivergencePolicy,
    RobotPlacement,
    robot_prefix,
)
from simulator.world.world import World

__all__ = [
    "ADULT_DEFAULT",
    "CameraRenderer",
    "DeviceKind",
    "DivergencePolicy",
    "FORCE_SENSORS",
    "HumanoidGeometry",
    "KID_DEFAULT",
    "known_models",
    "MOTOR_NAMES",
    "robot_model",
    "robot_prefix",
    "RobotModel",
    "RobotPlacement",
    "World",
]
