"""Getting up on the real MuJoCo robot after lying on the front."""

from __future__ import annotations

import pytest

from robot.motion import GetUpMotion, standing_posture

from .motion_world import RED1, OneRobot


@pytest.mark.parametrize("side", ["front", "back"])
def test_get_up_asks_no_joint_to_outrun_its_servo(side: str) -> None:
    """The keyframes stay within the catalogue servos: no target moves faster than the joint's
    no-load speed (targets beyond a joint's range count as the range's end, as the motor
    clamps them)."""
    from simulator.world.robots import KID_DEFAULT

    motors = {m.name: m for m in KID_DEFAULT.motors}
    motion = GetUpMotion(side)
    dt = 0.008

    def clamped(t: float) -> dict[str, float]:
        targets = motion.sample(t)
        return {
            n: min(max(v, motors[n].lower_rad), motors[n].upper_rad) for n, v in targets.items()
        }

    previous = clamped(0.0)
    for step in range(1, int(motion.duration_s / dt) + 2):
        now = clamped(step * dt)
        for name, value in now.items():
            speed = abs(value - previous[name]) / dt
            assert speed <= motors[name].max_velocity_rad_s, (name, round(step * dt, 3), speed)
        previous = now


@pytest.mark.parametrize("yaw", [0.0, 2.0])
def test_gets_up_from_the_front(yaw: float) -> None:
    robot = OneRobot(yaw_rad=yaw)
    robot.lay_down("front")
    assert robot.up < 0.5  # really lying
    motion = GetUpMotion("front", start=robot.joints)
    robot.run(motion.duration_s, lambda: motion.step(0.008), stop_on_fall=False)
    robot.run(2.0, standing_posture, stop_on_fall=False)
    assert robot.up > 0.9
    assert robot.position[2] > 0.3  # pelvis at standing height


def test_get_up_rejects_an_unknown_side() -> None:
    with pytest.raises(ValueError, match="side"):
        GetUpMotion("left")


@pytest.mark.parametrize("side", ["front", "back"])
def test_stub_controller_detects_the_fall_and_gets_up(side: str) -> None:
    from contracts.gamecontroller import GameState
    from contracts.geometry import Pose
    from robot.stub import GameInfo, Role, StubController

    robot = OneRobot()
    robot.lay_down(side)
    controller = StubController(role=Role.IDLE, start_pose=Pose(x_m=0.0, y_m=0.0, yaw_rad=0.0))
    game = GameInfo(phase=GameState.PLAYING)

    def tick() -> dict[str, float]:
        sensors = robot.sensors()
        return controller.tick(sensors, game)

    robot.run(12.0, tick, stop_on_fall=False)
    assert controller.stats.falls == 1
    assert controller.stats.get_ups >= 1
    assert robot.up > 0.9


@pytest.mark.parametrize("direction_rad", [0.3, 2.2, -2.5])
def test_pushed_over_robot_gets_back_up(direction_rad: float) -> None:
    import math

    from contracts.gamecontroller import GameState
    from contracts.geometry import Pose
    from robot.stub import GameInfo, Role, StubController

    robot = OneRobot(yaw_rad=1.0)
    controller = StubController(role=Role.IDLE, start_pose=Pose(x_m=0.0, y_m=0.0, yaw_rad=1.0))
    game = GameInfo(phase=GameState.PLAYING)
    push = robot.world.data.xfrc_applied[robot.torso]
    lowest = 1.0
    for step in range(int(20.0 / 0.008)):
        t = step * 0.008
        push[:3] = (
            (60 * math.cos(direction_rad), 60 * math.sin(direction_rad), 0) if 2 <= t < 2.15 else 0
        )
        sensors = robot.sensors()
        robot.command(controller.tick(sensors, game))
        robot.world.step()
        lowest = min(lowest, robot.up)
    assert lowest < 0.3  # the push did knock it over
    assert controller.stats.falls == 1
    assert robot.up > 0.9 and not controller.busy
    # it still knows which way it faces: the heading followed the fall and the get-up
    true_yaw = robot.world.snapshot().robot(RED1).yaw_rad
    error = math.atan2(
        math.sin(controller.world.pose.yaw_rad - true_yaw),
        math.cos(controller.world.pose.yaw_rad - true_yaw),
    )
    assert abs(error) < 0.2, (controller.world.pose.yaw_rad, true_yaw)
