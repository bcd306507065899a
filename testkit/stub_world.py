"""The stub robot controller on an in-process world (no network), for tests and benchmarks.

:func:`sense` gives a controller what it gets in a match (joints, IMU, a camera image when due).
:func:`run_reach` is one trial of ``hlvs bench stub``: can the striker find, reach and kick
the ball from 2 m away?
:func:`run_shot` is one trial of ``hlvs bench stub --scenario shots``: does the stub striker
score from in front of the goal? Each trial puts the ball 1.5-4 m in front of the goal the
striker attacks (x > 0, at most 60 degrees off the goal axis) and the striker 1 m from the ball
at a random (seeded) bearing and heading; optionally an opponent goalie (the stub goalie
behaviour, same perception) defends. The striker plays with the same controller and perception
as in a match. A trial succeeds when the ball crosses the goal line between the posts within the
time limit; it ends early when the ball leaves the field anywhere else.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from robot.stub.runner import CAMERA_PERIOD_MS  # the period the robot asks for in a match

AFTER_KICK_S = 4.0
MIN_KICK_M = 0.5


@dataclass(frozen=True, slots=True)
class ReachResult:
    success: bool
    kick_distance_m: float
    time_to_kick_s: float | None
    falls: int
    sim_time_s: float
    sightings: int


def run_reach(*, seed: int, distance_m: float, time_limit_s: float) -> ReachResult:
    """One trial of ``hlvs bench stub``: the striker ``distance_m`` from the ball at a seeded
    bearing and heading, in the look of ``texture_seed`` = ``seed``; it succeeds when the striker
    kicks within ``time_limit_s`` and the ball travels at least :data:`MIN_KICK_M`."""
    from contracts.gamecontroller import GameState
    from contracts.geometry import Pose
    from contracts.ids import RobotId, TeamColor
    from robot.stub.behaviour import GameInfo, Role
    from robot.stub.controller import StubController
    from simulator.world import CameraRenderer, RobotPlacement, World

    rng = np.random.default_rng(seed)
    bearing = float(rng.uniform(-math.pi, math.pi))
    heading = float(rng.uniform(-math.pi, math.pi))
    robot = RobotId(TeamColor.RED, 1)
    x, y = distance_m * math.cos(bearing), distance_m * math.sin(bearing)
    world = World.create(
        field_class="kid",
        robots=[RobotPlacement(id=robot, model="kid-default", x_m=x, y_m=y, yaw_rad=heading)],
        seed=seed,
    )
    controller = StubController(role=Role.STRIKER, start_pose=Pose(x_m=x, y_m=y, yaw_rad=heading))
    game = GameInfo(phase=GameState.PLAYING)
    ball_body = world.model.body("ball").id
    kicked_at_s: float | None = None
    ball_before: np.ndarray | None = None
    steps = int(time_limit_s * 1000 / world.step_ms)
    with CameraRenderer(world, 320, 240) as camera:
        step = 0
        while True:
            t_ms = world.sim_time_ms
            sensors = sense(world, robot, camera)
            kicks_before = controller.stats.kicks
            targets = controller.tick(sensors, game)
            if controller.stats.kicks > kicks_before and kicked_at_s is None:
                kicked_at_s = t_ms / 1000.0
                ball_before = world.data.xpos[ball_body].copy()
            for name, value in targets.items():
                world.set_motor_position(robot, name, value)
            world.step()
            step += 1
            if kicked_at_s is not None and world.sim_time_ms / 1000.0 > kicked_at_s + AFTER_KICK_S:
                break
            if kicked_at_s is None and step >= steps:
                break
    distance = 0.0
    if ball_before is not None:
        moved = world.data.xpos[ball_body] - ball_before
        distance = float(math.hypot(moved[0], moved[1]))
    return ReachResult(
        success=kicked_at_s is not None and distance >= MIN_KICK_M,
        kick_distance_m=distance,
        time_to_kick_s=kicked_at_s,
        falls=controller.stats.falls,
        sim_time_s=world.sim_time_ms / 1000.0,
        sightings=controller.stats.ball_sightings,
    )


GOAL_HALF_WIDTH_M = 1.3
HALF_LENGTH_M = 4.5
HALF_WIDTH_M = 3.0


def sense(world: Any, robot: Any, camera: Any | None) -> Any:
    """What the robot's controller gets in a match: joints, IMU, and a camera image when due
    (never without a ``camera``)."""
    from robot.stub.controller import Sensors

    t_ms = world.sim_time_ms
    image = None
    if camera is not None and t_ms % CAMERA_PERIOD_MS == 0:
        raw = camera.render(robot)
        image = np.frombuffer(raw, np.uint8).reshape(240, 320, 3)
    joints = {name[:-1]: value for name, value in world.read_positions(robot).items()}
    return Sensors(
        time_ms=t_ms,
        joints=joints,
        accel=world.read_accelerometer(robot),
        gyro=world.read_gyro(robot),
        image_bgr=image,
    )


@dataclass(frozen=True, slots=True)
class ShotResult:
    goal: bool
    time_to_goal_s: float | None
    outcome: str  # "goal", "out", "time"
    kicks: int
    falls: int
    sim_time_s: float


def shot_layout(seed: int) -> tuple[tuple[float, float], tuple[float, float, float]]:
    """Ball (x, y) and striker (x, y, yaw) in the world frame for trial ``seed``."""
    rng = np.random.default_rng(seed)
    while True:
        distance = float(rng.uniform(1.5, 4.0))
        angle = float(rng.uniform(-math.pi / 3, math.pi / 3))
        ball = (HALF_LENGTH_M - distance * math.cos(angle), distance * math.sin(angle))
        bearing = float(rng.uniform(-math.pi, math.pi))
        robot = (ball[0] + math.cos(bearing), ball[1] + math.sin(bearing))
        if abs(ball[1]) < 2.6 and abs(robot[1]) < 2.7 and robot[0] < HALF_LENGTH_M - 0.2:
            return ball, (robot[0], robot[1], float(rng.uniform(-math.pi, math.pi)))


def run_shot(*, seed: int, time_limit_s: float, goalie: bool) -> ShotResult:
    from contracts.gamecontroller import GameState
    from contracts.geometry import Pose
    from contracts.ids import RobotId, TeamColor
    from referee.snapshot import PlaceBall
    from robot.motion import SERVO_PID
    from robot.stub.behaviour import GameInfo, Role
    from robot.stub.controller import StubController
    from simulator.world import CameraRenderer, RobotPlacement, World

    ball, (x, y, yaw) = shot_layout(seed)
    striker = RobotId(TeamColor.RED, 1)
    placements = [RobotPlacement(id=striker, model="kid-default", x_m=x, y_m=y, yaw_rad=yaw)]
    start = Pose(x_m=x, y_m=y, yaw_rad=yaw)
    players = [(striker, StubController(role=Role.STRIKER, start_pose=start))]
    if goalie:
        keeper = RobotId(TeamColor.BLUE, 1)
        gx, gyaw = HALF_LENGTH_M - 0.5, math.pi
        placements.append(
            RobotPlacement(id=keeper, model="kid-default", x_m=gx, y_m=0.0, yaw_rad=gyaw)
        )
        # the goalie's own frame: it defends x < 0
        keeper_start = Pose(x_m=-gx, y_m=0, yaw_rad=0)
        players.append((keeper, StubController(role=Role.GOALIE, start_pose=keeper_start)))
    world = World.create(field_class="kid", robots=placements, seed=seed)
    world.apply(PlaceBall(position=(ball[0], ball[1], world.field.ball_radius_m)))
    for robot, _ in players:
        for name in world.motor_names(robot):
            world.set_motor_pid(robot, name, *SERVO_PID)
    game = GameInfo(phase=GameState.PLAYING)
    ball_body = world.model.body("ball").id
    steps = int(time_limit_s * 1000 / world.step_ms)
    outcome, goal_at = "time", None
    with CameraRenderer(world, 320, 240) as camera:
        for _ in range(steps):
            for robot, controller in players:
                sensors = sense(world, robot, camera)
                for name, value in controller.tick(sensors, game).items():
                    world.set_motor_position(robot, name, value)
            world.step()
            bx, by = (float(v) for v in world.data.xpos[ball_body][:2])
            if bx > HALF_LENGTH_M + world.field.ball_radius_m and abs(by) < GOAL_HALF_WIDTH_M:
                outcome, goal_at = "goal", world.sim_time_ms / 1000.0
                break
            if abs(bx) > HALF_LENGTH_M + 0.1 or abs(by) > HALF_WIDTH_M + 0.1:
                outcome = "out"
                break
    stats = players[0][1].stats
    return ShotResult(
        goal=outcome == "goal",
        time_to_goal_s=goal_at,
        outcome=outcome,
        kicks=stats.kicks,
        falls=stats.falls,
        sim_time_s=world.sim_time_ms / 1000.0,
    )


__all__ = ["ReachResult", "ShotResult", "run_reach", "run_shot", "sense", "shot_layout"]
