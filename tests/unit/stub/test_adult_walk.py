"""The adult-size robot under the stub: it rises from straight legs, walks and plays the ball."""

from __future__ import annotations

import math
from collections.abc import Callable

import pytest

from contracts.gamecontroller import GameState
from contracts.geometry import Pose
from referee.snapshot import TeleportRobot
from robot.motion import (
    KickMotion,
    WalkEngine,
    default_walk_params,
    kinematics,
    standing_posture,
)
from robot.stub import GameInfo, Role, StubController
from robot.stub.world_model import WorldModel
from simulator.world import CameraRenderer

from .motion_world import RED1, OneRobot

ADULT = "adult-default"


def walker(
    robot: OneRobot, engine: WalkEngine, vx: float, vy: float, vyaw: float
) -> Callable[[], dict[str, float]]:
    return lambda: engine.step(0.008, vx, vy, vyaw, accel=robot.accel, gyro=robot.gyro)


def test_rises_from_straight_legs_without_falling() -> None:
    """Placed with all joints at zero, it eases into the stance instead of bending its knees at
    the servos' full speed (which throws it over backwards after about 1.5 s), at the start and
    after every teleport."""
    robot = OneRobot(x_m=-2.0, model=ADULT)
    controller = StubController(
        role=Role.STRIKER,
        start_pose=Pose(x_m=-2.0, y_m=0.0, yaw_rad=0.0),
        model=ADULT,
        field_class="adult",
    )
    game = GameInfo(phase=GameState.PLAYING)
    busy: set[str] = set()

    def tick() -> dict[str, float]:
        targets = controller.tick(robot.sensors(), game)
        busy.add(controller.busy)
        return targets

    assert robot.run(5.0, tick), "fell"
    assert "rise" in busy
    assert controller.stats.falls == 0
    assert robot.up > 0.9
    # the referee moves it (kick-off, penalty): joints back to zero, it rises again
    robot.world.apply(TeleportRobot(robot=RED1, pose=Pose(x_m=-3.0, y_m=1.0, yaw_rad=1.0)))
    busy.clear()
    assert robot.run(4.0, tick), "fell after being moved"
    assert "rise" in busy
    assert controller.stats.falls == 0


def test_walks_forward_for_10_s_without_falling() -> None:
    """At the striker's cruise speed (0.4 m/s) it covers about 3.4 m in 10 s, the ramp-up
    included."""
    robot = OneRobot(model=ADULT)
    robot.rise()
    start = robot.position
    engine = WalkEngine(model=ADULT)
    assert engine.params.cruise_vx_m_s == 0.4
    assert robot.run(10.0, walker(robot, engine, 0.4, 0.0, 0.0)), "fell while walking"
    moved = robot.position - start
    assert moved[0] >= 3.0
    assert abs(moved[1]) < 0.2 * moved[0]


def test_turns_while_walking_without_falling() -> None:
    """Walking at 0.4 m/s and turning at 0.4 rad/s, as the striker does on its way to the ball."""
    robot = OneRobot(model=ADULT)
    robot.rise()
    engine = WalkEngine(model=ADULT)
    start_yaw = robot.yaw
    assert robot.run(8.0, walker(robot, engine, 0.4, 0.0, 0.4)), "fell while turning"
    assert math.remainder(robot.yaw - start_yaw, 2 * math.pi) > 1.5


def test_kicks_without_falling() -> None:
    """The adult's kick from a stand, the ball on its kick spot in front of the right foot, sends
    the ball more than 3.5 m on and leaves the robot standing (4.2 m on the spot; 3.0-4.3 m over
    the window in which the stub kicks, 5 cm either way)."""
    robot = OneRobot(x_m=-2.0, model=ADULT)
    robot.rise()
    kin = kinematics(ADULT)
    assert kin.kick_ball_x_m is not None
    spot_x = robot.position[0] + kin.kick_ball_x_m
    side = kin.leg.hip_offset_y_m + default_walk_params(ADULT).foot_y_offset_m + 0.02
    robot.place_ball(spot_x, -side)
    kick = KickMotion(foot="right", model=ADULT, start=standing_posture(ADULT))
    assert robot.run(kick.duration_s + 1.5, lambda: kick.step(0.008)), "fell kicking"
    assert robot.run(6.0, lambda: standing_posture(ADULT)), "fell after the kick"
    moved = robot.ball_position[:2] - (spot_x, -side)
    assert moved[0] > 3.5
    assert abs(moved[1]) < 0.2 * moved[0]


def test_striker_walks_to_the_ball_and_kicks_it() -> None:
    """Placed with straight legs 2 m behind the ball, turned away from it, the adult striker
    rises, walks to the ball by its head camera and kicks it towards the opponent goal (first
    kick after 13.3 s here; on six more starts between 11.6 and 15.7 s, never falling)."""
    start = Pose(x_m=-3.0, y_m=0.5, yaw_rad=0.3)
    robot = OneRobot(x_m=start.x_m, y_m=start.y_m, yaw_rad=start.yaw_rad, model=ADULT)
    robot.place_ball(-1.0, 0.0)
    controller = StubController(
        role=Role.STRIKER, start_pose=start, model=ADULT, field_class="adult"
    )
    game = GameInfo(phase=GameState.PLAYING)
    with CameraRenderer(robot.world, 320, 240) as camera:
        for _ in range(int(20.0 / 0.008)):
            robot.command(controller.tick(robot.sensors(camera), game))
            robot.world.step()
            if controller.stats.kicks and not controller.busy:
                break
    assert controller.stats.falls == 0
    assert controller.stats.kicks >= 1
    assert robot.up > 0.9
    assert robot.ball_position[0] > -1.0 + 1.0  # kicked at least 1 m towards the goal


def test_ball_sightings_are_averaged_with_a_gain_below_one() -> None:
    """The adult averages its ball sightings (its sway moves the ball in its images by several
    centimetres); a ball seen far from where it was, or after a while, is taken as seen."""
    exact = WorldModel(Pose(x_m=0.0, y_m=0.0, yaw_rad=0.0))
    exact.see_ball(0, 1.0, 0.0)
    exact.see_ball(96, 1.0, 0.1)
    assert exact.ball_field == (1.0, 0.1)
    averaged = WorldModel(Pose(x_m=0.0, y_m=0.0, yaw_rad=0.0), ball_gain=0.3)
    averaged.see_ball(0, 1.0, 0.0)
    averaged.see_ball(96, 1.0, 0.1)
    assert averaged.ball_field is not None
    assert averaged.ball_field[1] == pytest.approx(0.03)
    averaged.see_ball(192, 2.0, 0.0)  # kicked away
    assert averaged.ball_field == (2.0, 0.0)
    averaged.see_ball(2000, 2.0, 0.2)  # not seen for 1.8 s
    assert averaged.ball_field == (2.0, 0.2)
