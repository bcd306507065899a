"""The stub follows where the referee puts it: its half-time pose when a half begins, its
re-entry point when a penalty ends during play."""

from __future__ import annotations

import math

import pytest

from contracts.gamecontroller import GameState
from contracts.geometry import Pose
from robot.stub import GameInfo, Role, StubController
from robot.stub.runner import RefereePlacement

from .motion_world import OneRobot

TEAM_FILE_POSE = Pose(x_m=-0.8, y_m=-3.1, yaw_rad=math.pi / 2)


def _first_half_ends_with_a_penalty(controller: StubController,
                                    placement: RefereePlacement) -> None:
    for game in (GameInfo(phase=GameState.PLAYING, on_left=True),
                 GameInfo(phase=GameState.PLAYING, on_left=True, penalised=True),
                 GameInfo(phase=GameState.FINISHED, on_left=True, penalised=True)):
        placement.follow(controller, game)


@pytest.mark.parametrize("lifted_later", [False, True])
def test_a_penalty_the_half_cuts_short_leaves_the_robot_at_its_half_time_pose(
    lifted_later: bool,
) -> None:
    """Red was penalised when the first half ended; the second half places it at the mirror
    image of its team-file pose, on the right. Its belief is that pose in its turned frame,
    whether the penalty is lifted in the packet that starts the half or in a later one."""
    controller = StubController(role=Role.STRIKER, start_pose=TEAM_FILE_POSE, detect_side=True)
    placement = RefereePlacement(TEAM_FILE_POSE)
    _first_half_ends_with_a_penalty(controller, placement)
    second_half = GameInfo(phase=GameState.INITIAL, first_half=False, on_left=False)
    if lifted_later:
        placement.follow(controller, GameInfo(phase=GameState.INITIAL, first_half=False,
                                               on_left=False, penalised=True))
    placement.follow(controller, second_half)
    robot = OneRobot(x_m=0.8, y_m=-3.1, yaw_rad=math.pi / 2)  # where the referee put it
    robot.command(controller.tick(robot.sensors(), second_half))
    assert controller.mirrored is True
    pose = controller.world.pose
    assert (pose.x_m, pose.y_m) == pytest.approx((-0.8, 3.1), abs=1e-6)
    assert pose.yaw_rad == pytest.approx(-math.pi / 2, abs=1e-6)


def test_a_penalty_that_ends_during_play_puts_the_robot_at_its_reentry_point() -> None:
    controller = StubController(role=Role.STRIKER, start_pose=TEAM_FILE_POSE, detect_side=True)
    placement = RefereePlacement(TEAM_FILE_POSE)
    for game in (GameInfo(phase=GameState.PLAYING, on_left=True),
                 GameInfo(phase=GameState.PLAYING, on_left=True, penalised=True),
                 GameInfo(phase=GameState.PLAYING, on_left=True)):
        placement.follow(controller, game)
    pose = controller.world.pose  # the touch line of its own half it was nearer to
    assert (pose.x_m, pose.y_m, pose.yaw_rad) == pytest.approx((-3.0, -3.2, math.pi / 2))


def test_a_robot_placed_upright_while_getting_up_knows_at_once_it_stands() -> None:
    """A half ends while the robot gets up; the referee places it upright at its half-time
    pose. With the new half (its pose reset) the get-up is dropped and the attitude is taken
    from the accelerometer afresh: it walks its READY without falling, instead of balancing for
    a second against the fall it remembers."""
    from referee.snapshot import TeleportRobot

    from .motion_world import RED1

    robot = OneRobot(x_m=-1.0, y_m=-2.0, yaw_rad=math.pi / 2)
    controller = StubController(role=Role.STRIKER, start_pose=TEAM_FILE_POSE)
    playing = GameInfo(phase=GameState.PLAYING, on_left=True)
    robot.lay_down("front")
    assert robot.run(1.5, lambda: controller.tick(robot.sensors(), playing),
                     stop_on_fall=False)
    assert controller.busy == "get-up"
    assert controller.attitude.attitude.pitch_rad > 0.3  # it knows it is not upright
    robot.world.apply(TeleportRobot(robot=RED1, pose=Pose(x_m=0.8, y_m=-3.1,
                                                           yaw_rad=math.pi / 2)))
    second_half = GameInfo(phase=GameState.READY, first_half=False, on_left=False,
                           our_kick_off=False)
    placement = RefereePlacement(TEAM_FILE_POSE)
    placement.follow(controller, playing)
    placement.follow(controller, second_half)
    assert controller.busy == ""
    robot.command(controller.tick(robot.sensors(), second_half))
    att = controller.attitude.attitude
    assert abs(att.pitch_rad) < 0.1 and abs(att.roll_rad) < 0.1
    assert robot.run(6.0, lambda: controller.tick(robot.sensors(), second_half)), "fell"
