"""The league's test robot (``simulator.world.robots.league``): the crouched Darwin-OP the league's
referee test scenarios push balls and robots into, for ``hlvs referee test --world league`` only."""

from __future__ import annotations

import math

import pytest

from referee.snapshot import PlaceBall
from simulator.world import RobotPlacement, World, known_models, robot_model
from tests.unit.world.conftest import RED_1

LEAGUE = "league-test-kid"


def run_steps(world: World, n: int) -> None:
    for _ in range(n):
        world.step()


def _world(model: str, *, yaw: float = 0.0) -> World:
    robot = RobotPlacement(id=RED_1, model=model, x_m=1.0, y_m=0.0, yaw_rad=yaw)
    return World.create(field_class="kid", robots=[robot], seed=1)


def test_it_stands_crouched_where_the_league_robot_stands() -> None:
    """Darwin-opHinge2Robocup.proto keeps its stored crouch (LegUpper 1.15, LegLower 2.25, Ankle
    1.23 rad) with its origin 0.24 m up (the team files' halfTimeStartingPose height)."""
    model = robot_model(LEAGUE)
    assert model.standing_height_m == pytest.approx(0.24, abs=0.002)
    world = _world(LEAGUE)
    run_steps(world, 250)  # 2 s
    robot = world.snapshot().robot(RED_1)
    assert not robot.fallen
    assert robot.position[2] == pytest.approx(0.24, abs=0.012)  # on the soft turf
    info = world.index.by_id[RED_1]
    m, d = world.model, world.data
    knee = float(d.qpos[m.joint("red_1/LegLowerL").qposadr[0]])
    assert knee == pytest.approx(2 * 1.126, abs=0.03)
    # the knees reach about 0.11 m in front of the origin at the ball's height (the proto's
    # knee boxes: 0.109), the body weighs about the Darwin-OP's 2.93 kg
    front = max(
        d.geom_xpos[g][0] + sum(abs(d.geom_xmat[g][k]) * m.geom_size[g][k] for k in range(3))
        for g in range(m.ngeom)
        if m.geom(g).name.startswith("red_1/leg:")  # thigh and shank boxes: their front corner
    )
    assert front - 1.0 == pytest.approx(0.109, abs=0.005)
    mass = float(m.body_subtreemass[info.torso_body])
    assert mass == pytest.approx(2.93, abs=0.2)


@pytest.mark.parametrize(("model", "bounces"), [(LEAGUE, True), ("kid-default", False)])
def test_a_ball_rolled_at_its_legs_bounces_back(model: str, bounces: bool) -> None:
    """The league's scenarios push the ball into the robot's legs (a touch before a set play's
    kick, kick_off/scenario_3): the crouched legs send it back; our straight-legged robot lets
    it roll in between its feet, and a ball meant to touch it leaves the field behind it."""
    world = _world(model, yaw=math.pi)  # facing -x, the ball in front of it
    r = world.field.ball_radius_m
    world.apply(PlaceBall(position=(0.8, 0.0, r), velocity=(1.2, 0.0, 0.0)))
    run_steps(world, 60)
    x = float(world.snapshot().ball.position[0])
    assert (x < 0.75) is bounces, x


def test_no_team_can_choose_it() -> None:
    from orchestrator.config import BUILT_IN_MODELS

    assert LEAGUE not in known_models() and LEAGUE not in BUILT_IN_MODELS
    assert robot_model(LEAGUE).name == LEAGUE
    assert robot_model("kid-default").crouch_rad == 0.0
    assert not any(robot_model("kid-default").standing_pose_rad)


def test_a_ball_rolled_into_its_heel_stops_against_its_ankle_servos() -> None:
    """The Darwin-OP's foot carries its ankle servos' box, 0.062 m behind the ankle and 0.021 to
    0.066 m above the ground (Darwin-opHinge2Robocup.proto:1006-1012): a ball pushed into the
    robot's heel (throw_in/ball_distance, blue standing behind the touch line with its back to
    the ball) stops against it, where it would ride up a 13 mm sole and roll on."""
    world = _world(LEAGUE)  # facing +x, the ball behind it
    run_steps(world, 125)
    r = world.field.ball_radius_m
    world.apply(PlaceBall(position=(0.85, 0.0, r), velocity=(0.6, 0.0, 0.0)))
    xs, zs = [], []
    for _ in range(100):
        world.step()
        ball = world.snapshot().ball.position
        xs.append(float(ball[0]))
        zs.append(float(ball[2]))
    heel = 1.0 - 0.062  # the box's back face (the soft contact lets the ball in about 1 cm)
    assert heel - r < max(xs) < heel - r + 0.02, max(xs)
    assert xs[-1] < max(xs) - 0.1  # sent back
    assert max(zs) < r + 0.005, max(zs)
