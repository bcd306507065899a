"""A lightweight snapshot source for referee tests that need whole 2 x 600 s games.

Robots stand where they are put (no physics, never fallen); the ball rolls in a straight line
with a constant deceleration and ignores robots and goals. Referee commands are applied as the
real world applies them. Far faster than MuJoCo, so a full game runs in seconds.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from contracts.field import KID_FIELD, FieldGeometry
from contracts.ids import RobotId
from referee.snapshot import (
    BallState,
    PlaceBall,
    RemoveRobot,
    RestoreRobot,
    RobotState,
    SetLimp,
    TeleportRobot,
    Vec3,
    WorldCommand,
    WorldSnapshot,
)

DECELERATION_M_S2 = 0.4


@dataclass
class _Robot:
    x: float
    y: float
    yaw: float
    limp: bool = False
    removed: bool = False


class KinematicWorld:
    def __init__(
        self,
        robots: dict[RobotId, tuple[float, float, float]],
        *,
        field: FieldGeometry = KID_FIELD,
        step_ms: int = 8,
    ) -> None:
        self.field = field
        self.step_ms = step_ms
        self.sim_time_ms = 0
        self.robots = {rid: _Robot(*pose) for rid, pose in robots.items()}
        self.ball: Vec3 = (0.0, 0.0, field.ball_radius_m)
        self.ball_velocity: Vec3 = (0.0, 0.0, 0.0)
        self.last_ball_toucher: RobotId | None = None
        self.last_ball_touch_ms: int | None = None

    def touch(self, robot: RobotId) -> None:
        """``robot`` touches the ball now (as the world records the last toucher)."""
        self.last_ball_toucher, self.last_ball_touch_ms = robot, self.sim_time_ms

    def step(self) -> None:
        dt = self.step_ms / 1000.0
        vx, vy, _ = self.ball_velocity
        speed = math.hypot(vx, vy)
        if speed > 0:
            slower = max(0.0, speed - DECELERATION_M_S2 * dt)
            vx, vy = vx * slower / speed, vy * slower / speed
            x, y, z = self.ball
            self.ball = (x + vx * dt, y + vy * dt, z)
            self.ball_velocity = (vx, vy, 0.0)
        self.sim_time_ms += self.step_ms

    def snapshot(self) -> WorldSnapshot:
        robots = tuple(
            RobotState(
                id=rid,
                position=(r.x, r.y, 0.4),
                yaw_rad=r.yaw,
                center_of_mass=(r.x, r.y, 0.3),
                velocity=(0.0, 0.0, 0.0),
                hull_points=((r.x, r.y - 0.1), (r.x, r.y + 0.1)),
                limp=r.limp,
                removed=r.removed,
            )
            for rid, r in self.robots.items()
        )
        return WorldSnapshot(
            sim_time_ms=self.sim_time_ms,
            ball=BallState(position=self.ball, velocity=self.ball_velocity),
            robots=robots,
            last_ball_toucher=self.last_ball_toucher,
            last_ball_touch_ms=self.last_ball_touch_ms,
        )

    def apply(self, command: WorldCommand) -> None:
        if isinstance(command, PlaceBall):
            self.ball, self.ball_velocity = command.position, command.velocity
            return
        robot = self.robots[command.robot]
        if isinstance(command, TeleportRobot | RestoreRobot):
            robot.x, robot.y, robot.yaw = command.pose.x_m, command.pose.y_m, command.pose.yaw_rad
            robot.removed = robot.removed and isinstance(command, TeleportRobot)
        elif isinstance(command, SetLimp):
            robot.limp = command.limp
        elif isinstance(command, RemoveRobot):
            robot.removed = True
            robot.x, robot.y = 50.0, 10.0 + command.robot.number
