"""Referee commands applied to the world: place the ball, teleport, limp, remove, restore."""

from __future__ import annotations

import logging
import math
from typing import Protocol

import mujoco
import numpy as np

from contracts import RobotId, TeamColor
from referee import (
    PlaceBall,
    RemoveRobot,
    RestoreRobot,
    SetLimp,
    TeleportRobot,
    Vec3,
    WorldCommand,
)
from simulator.world.indices import WorldIndex
from simulator.world.motors import MotorBank


class CommandTarget(Protocol):
    """What the commands change in a world (:class:`simulator.world.world.World` is one); the
    world calls these functions, they never call back into it."""

    model: mujoco.MjModel
    data: mujoco.MjData
    index: WorldIndex
    robot_ids: tuple[RobotId, ...]
    motors: MotorBank
    limp: list[bool]
    removed: list[bool]
    parked_qpos: dict[int, np.ndarray]

logger = logging.getLogger(__name__)

PARK_X_M = 50.0
PARK_Y_M = 10.0
STANDING_CLEARANCE_M = 0.002


def apply(world: CommandTarget, command: WorldCommand) -> None:
    if isinstance(command, PlaceBall):
        place_ball(world, command.position, command.velocity)
        return
    number = world.index.by_id[command.robot].number
    if isinstance(command, TeleportRobot):
        teleport(world, number, command.pose.x_m, command.pose.y_m, command.pose.yaw_rad)
    elif isinstance(command, SetLimp):
        set_limp(world, number, command.limp)
    elif isinstance(command, RemoveRobot):
        remove(world, number)
    elif isinstance(command, RestoreRobot):
        restore(world, number, command.pose.x_m, command.pose.y_m, command.pose.yaw_rad)
    mujoco.mj_forward(world.model, world.data)


def place_ball(world: CommandTarget, position: Vec3, velocity: Vec3) -> None:
    q, d = world.index.ball_qpos, world.index.ball_dof
    world.data.qpos[q : q + 3] = position
    world.data.qpos[q + 3 : q + 7] = (1.0, 0.0, 0.0, 0.0)
    world.data.qvel[d : d + 3] = velocity
    world.data.qvel[d + 3 : d + 6] = 0.0
    mujoco.mj_forward(world.model, world.data)


def _standing_qpos(world: CommandTarget, number: int, x: float, y: float, yaw: float) -> np.ndarray:
    robot = world.index.robots[number]
    start, end = robot.qpos_range
    qpos: np.ndarray = np.array(world.data.qpos[start:end], dtype=np.float64)
    qpos[0:3] = (x, y, robot.model.standing_height_m + STANDING_CLEARANCE_M)
    qpos[3:7] = (math.cos(yaw / 2), 0.0, 0.0, math.sin(yaw / 2))
    qpos[robot.motor_qpos - start] = robot.model.standing_pose_rad
    return qpos


def teleport(world: CommandTarget, number: int, x: float, y: float, yaw: float) -> None:
    """Standing posture (the model's standing pose: all joints at zero for the built-in models)
    at (x, y, yaw), velocities zeroed."""
    robot = world.index.robots[number]
    start, end = robot.qpos_range
    world.data.qpos[start:end] = _standing_qpos(world, number, x, y, yaw)
    world.data.qvel[robot.dof_range[0] : robot.dof_range[1]] = 0.0
    world.motors.hold(robot.actuators, np.asarray(robot.model.standing_pose_rad, dtype=float))


def set_limp(world: CommandTarget, number: int, limp: bool) -> None:
    """Take the robot out of its team's control (``limp``) or give it back. While out of
    control (a penalised robot at its re-entry spot) the world holds it in its standing pose,
    as a referee carries a removed robot, instead of letting it fold up and fall: its team's
    motor commands wait until it is released (:mod:`simulator.api.session`)."""
    robot = world.index.robots[number]
    world.limp[number] = limp
    pose = np.asarray(robot.model.standing_pose_rad, dtype=float) if limp else None
    world.motors.set_held(robot.actuators, pose)
    logger.info("%s %s", robot.id, "held out of play" if limp else "under control again")


def remove(world: CommandTarget, number: int) -> None:
    """Park the robot far outside the field, frozen and without collisions."""
    robot = world.index.robots[number]
    if world.removed[number]:
        return
    side = 1.0 if robot.id.team is TeamColor.RED else -1.0
    y = side * (PARK_Y_M + robot.id.number)
    teleport(world, number, PARK_X_M, y, 0.0)
    world.parked_qpos[number] = world.data.qpos[robot.qpos_range[0] : robot.qpos_range[1]].copy()
    world.model.geom_contype[robot.geoms] = 0
    world.model.geom_conaffinity[robot.geoms] = 0
    world.removed[number] = True
    logger.info("%s removed from the world", robot.id)


def restore(world: CommandTarget, number: int, x: float, y: float, yaw: float) -> None:
    robot = world.index.robots[number]
    if world.removed[number]:
        from simulator.world.scene import robot_conaffinity

        world.model.geom_contype[robot.geoms] = 1 << number
        world.model.geom_conaffinity[robot.geoms] = robot_conaffinity(len(world.robot_ids))
        world.removed[number] = False
        world.parked_qpos.pop(number, None)
        logger.info("%s restored", robot.id)
    teleport(world, number, x, y, yaw)


def hold_parked(world: CommandTarget) -> None:
    """Keep removed robots frozen at their parking spots (after every step)."""
    for number, qpos in world.parked_qpos.items():
        robot = world.index.robots[number]
        world.data.qpos[robot.qpos_range[0] : robot.qpos_range[1]] = qpos
        world.data.qvel[robot.dof_range[0] : robot.dof_range[1]] = 0.0
