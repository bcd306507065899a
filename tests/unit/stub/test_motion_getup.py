"""Getting up on the real MuJoCo robot after lying on the front or the back (kid and adult)."""

from __future__ import annotations

import math

import pytest

from robot.motion import GetUpMotion, standing_posture

from .motion_world import RED1, OneRobot

MODELS = ["kid-default", "adult-default"]


@pytest.mark.parametrize("model", MODELS)
@pytest.mark.parametrize("side", ["front", "back"])
def test_get_up_asks_no_joint_to_outrun_its_servo(side: str, model: str) -> None:
    """The keyframes stay within the model's catalogue servos: no target moves faster than the
    joint's no-load speed (targets beyond a joint's range count as the range's end, as the motor
    clamps them)."""
    from simulator.world.robots import RobotModel, robot_model

    built_in = robot_model(model)
    assert isinstance(built_in, RobotModel)
    motors = {m.name: m for m in built_in.motors}
    motion = GetUpMotion(side, model=model)
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


@pytest.mark.parametrize("model", MODELS)
@pytest.mark.parametrize("yaw", [0.0, 2.0])
def test_gets_up_from_the_front(yaw: float, model: str) -> None:
    robot = OneRobot(yaw_rad=yaw, model=model)
    robot.lay_down("front")
    assert robot.up < 0.5  # really lying
    motion = GetUpMotion("front", model=model, start=robot.joints)
    robot.run(motion.duration_s, lambda: motion.step(0.008), stop_on_fall=False)
    robot.run(2.0, lambda: standing_posture(model), stop_on_fall=False)
    assert robot.up > 0.9
    assert robot.position[2] > 0.3 * robot.scale  # pelvis at standing height


def test_get_up_rejects_an_unknown_side() -> None:
    with pytest.raises(ValueError, match="side"):
        GetUpMotion("left")


@pytest.mark.parametrize("model", MODELS)
@pytest.mark.parametrize("side", ["front", "back"])
def test_stub_controller_detects_the_fall_and_gets_up(side: str, model: str) -> None:
    """Through the stub controller: one fall, and the first attempt stands (from the back: the
    roll onto the front, then the front get-up)."""
    from contracts.gamecontroller import GameState
    from contracts.geometry import Pose
    from robot.stub import GameInfo, Role, StubController

    robot = OneRobot(model=model)
    robot.lay_down(side)
    controller = StubController(
        role=Role.IDLE,
        start_pose=Pose(x_m=0.0, y_m=0.0, yaw_rad=0.0),
        model=model,
        field_class="kid" if model == "kid-default" else "adult",
    )
    game = GameInfo(phase=GameState.PLAYING)

    def tick() -> dict[str, float]:
        sensors = robot.sensors()
        return controller.tick(sensors, game)

    motions = 1 if side == "front" else 2
    seconds = sum(GetUpMotion(s, model=model).duration_s for s in ("front", "back")[:motions])
    robot.run(seconds + 2 * motions + 2.0, tick, stop_on_fall=False)
    assert controller.stats.falls == 1
    assert controller.stats.get_ups == motions
    assert robot.up > 0.9
    assert robot.position[2] > 0.3 * robot.scale


# the kid is pushed by 60 N for 0.15 s; the adult (8 times the mass) by 300 N for 0.2 s, standing
# up first from the straight legs it is placed with
PUSHES = {"kid-default": (60.0, 0.15, 20.0), "adult-default": (300.0, 0.2, 34.0)}


@pytest.mark.parametrize("model", MODELS)
@pytest.mark.parametrize("direction_rad", [0.3, 2.2, -2.5])
def test_pushed_over_robot_gets_back_up(direction_rad: float, model: str) -> None:
    from contracts.gamecontroller import GameState
    from contracts.geometry import Pose
    from robot.stub import GameInfo, Role, StubController

    robot = OneRobot(yaw_rad=1.0, model=model)
    if model != "kid-default":
        robot.rise()
    controller = StubController(
        role=Role.IDLE,
        start_pose=Pose(x_m=0.0, y_m=0.0, yaw_rad=1.0),
        model=model,
        field_class="kid" if model == "kid-default" else "adult",
    )
    game = GameInfo(phase=GameState.PLAYING)
    force, push_s, seconds = PUSHES[model]
    push = robot.world.data.xfrc_applied[robot.torso]
    lowest = 1.0
    for step in range(int(seconds / 0.008)):
        t = step * 0.008
        push[:3] = (
            (force * math.cos(direction_rad), force * math.sin(direction_rad), 0)
            if 2 <= t < 2 + push_s
            else 0
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
