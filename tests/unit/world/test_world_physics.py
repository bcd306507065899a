"""Ball and robot physics: bounce, roll to rest, standing, falling, determinism, divergence."""

from __future__ import annotations

import hashlib
import math
from pathlib import Path

import numpy as np
import pytest

from contracts.ids import RobotId, TeamColor
from referee.snapshot import BodyPart, PlaceBall
from simulator.errors import PhysicsDivergence
from simulator.recorder import Recorder
from simulator.world import RobotPlacement, World
from tests.unit.world.conftest import RED_1, eight_robots, run_steps


def test_dropped_ball_bounces_then_rolls_to_rest() -> None:
    world = World.create(field_class="kid", robots=[], seed=1)
    r = world.field.ball_radius_m
    world.apply(PlaceBall(position=(0.0, 0.0, 1.0 + r), velocity=(0.0, 0.0, 0.0)))
    heights = []
    for _ in range(250):
        world.step()
        heights.append(world.snapshot().ball.position[2] - r)
    first_contact = next(i for i, h in enumerate(heights) if h < 0.005)
    apex = max(heights[first_contact : first_contact + 100])
    assert 0.45 < apex < 0.75  # restitution about 0.76 (sqrt of the height ratio)
    world.apply(PlaceBall(position=(-2.0, 0.0, r), velocity=(4.0, 0.0, 0.0)))
    run_steps(world, 1000)  # 8 s
    ball = world.snapshot().ball
    assert 3.0 < ball.position[0] + 2.0 < 9.0  # rolled several metres
    assert math.hypot(ball.velocity[0], ball.velocity[1]) < 0.02  # and stopped
    assert ball.position[2] == pytest.approx(r, abs=0.005)


@pytest.mark.parametrize("model", ["kid-default", "adult-default"])
def test_robot_with_motors_at_zero_stands_ten_seconds(model: str) -> None:
    placement = RobotPlacement(id=RED_1, model=model, x_m=-1.0, y_m=0.5, yaw_rad=0.3)
    world = World.create(field_class="kid" if model == "kid-default" else "adult",
                         robots=[placement], seed=1)  # fmt: skip
    start = world.snapshot().robots[0]
    run_steps(world, 1250)
    robot = world.snapshot().robots[0]
    assert not robot.fallen
    assert robot.ground_contacts == frozenset({BodyPart.FOOT})
    assert robot.position[2] == pytest.approx(start.position[2], abs=0.01)
    assert math.dist(robot.position[:2], start.position[:2]) < 0.01
    assert robot.yaw_rad == pytest.approx(0.3, abs=0.01)


def test_pushed_robot_is_reported_fallen(one_robot_world: World) -> None:
    world = one_robot_world
    torso = world.model.body("red_1/torso").id
    world.data.xfrc_applied[torso, 0] = 40.0  # N, 0.2 s push forward
    run_steps(world, 25)
    world.data.xfrc_applied[:] = 0.0
    run_steps(world, 300)
    robot = world.snapshot().robots[0]
    assert robot.fallen
    assert robot.touches_ground_outside_feet
    assert robot.position[2] < 0.2


def _record(tmp: Path, seed: int) -> bytes:
    world = World.create(field_class="kid", robots=eight_robots(), seed=seed,
                         initial_joint_noise_rad=0.02)  # fmt: skip
    world.apply(PlaceBall(position=(0.0, 0.0, 0.07), velocity=(1.5, 0.5, 0.0)))
    path = tmp / f"run-{seed}-{len(list(tmp.iterdir()))}.hlvsrec"
    with Recorder(path, world, match_id="determinism") as recorder:
        for step in range(250):
            world.set_motor_position(RED_1, "LegUpperL", 0.3 * math.sin(step / 20))
            world.step()
            recorder.record(world, {"state": "PLAYING", "secs_remaining": 600 - step // 125})
    return path.read_bytes()


def test_same_seed_same_inputs_give_identical_recordings(tmp_path: Path) -> None:
    first = _record(tmp_path, seed=11)
    second = _record(tmp_path, seed=11)
    other = _record(tmp_path, seed=12)
    assert hashlib.sha256(first).digest() == hashlib.sha256(second).digest()
    assert first != other  # the seed drives the initial joint noise


def test_divergence_fails_with_the_typed_error(one_robot_world: World) -> None:
    world = one_robot_world
    dof = world.model.joint("red_1/Neck").dofadr[0]
    world.data.qvel[dof] = np.inf
    with pytest.raises(PhysicsDivergence) as caught:
        world.step()
    assert caught.value.policy == "fail"
    assert "red_1/Neck" in caught.value.warning
    assert caught.value.sim_time_ms == 8


def test_mujoco_s_warnings_go_to_the_log_not_to_a_file_in_the_working_folder(
        one_robot_world: World, tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
        caplog: pytest.LogCaptureFixture) -> None:
    import logging

    import mujoco

    from simulator.world import divergence

    monkeypatch.chdir(tmp_path)
    world = one_robot_world
    world.data.qvel[world.model.joint("red_1/Neck").dofadr[0]] = np.nan
    with caplog.at_level(logging.DEBUG, logger="simulator.mujoco"):
        with pytest.raises(PhysicsDivergence):
            world.step()
        assert not (tmp_path / "MUJOCO_LOG.TXT").exists()
        said = [r for r in caplog.records if r.name == "simulator.mujoco"]
        assert [r.levelno for r in said] == [logging.DEBUG]  # the world reports it itself
        assert "Nan, Inf or huge value in QVEL" in said[0].getMessage()
        caplog.clear()
        monkeypatch.setattr(divergence, "_last_said", {})
        handler = mujoco.get_mju_user_warning()
        assert handler is not None
        for n in (100, 101, 102):  # the same kind three times: said once
            handler(f"Pre-allocated constraint buffer is full. Increase memory to {n}M.")
        handler("Something else entirely")
    said = [(r.levelno, r.getMessage()) for r in caplog.records if r.name == "simulator.mujoco"]
    assert said == [
        (logging.WARNING, "MuJoCo: Pre-allocated constraint buffer is full. Increase memory "
                          "to 100M."),
        (logging.WARNING, "MuJoCo: Something else entirely"),
    ]
    assert not (tmp_path / "MUJOCO_LOG.TXT").exists()


def test_divergence_reset_robot_policy_keeps_running() -> None:
    robots = [
        RobotPlacement(id=RED_1, model="kid-default", x_m=-1.0, y_m=0.0, yaw_rad=0.0),
        RobotPlacement(id=RobotId(TeamColor.BLUE, 2), model="kid-default", x_m=1.0,
                       y_m=1.0, yaw_rad=0.0),
    ]  # fmt: skip
    world = World.create(field_class="kid", robots=robots, seed=3, divergence_policy="reset_robot")
    world.apply(PlaceBall(position=(0.5, -1.0, 0.07), velocity=(0.0, 0.0, 0.0)))
    run_steps(world, 10)
    dof = world.model.joint("blue_2/Head").dofadr[0]
    world.data.qvel[dof] = np.nan
    run_steps(world, 50)
    snap = world.snapshot()
    assert world.sim_time_ms == 60 * 8
    assert snap.ball.position[0] == pytest.approx(0.5, abs=0.01)  # the rest was not reset
    blue = snap.robot(RobotId(TeamColor.BLUE, 2))
    assert blue.position[:2] == pytest.approx((1.0, 1.0), abs=0.02)
    assert not blue.fallen
    assert np.isfinite(world.data.qpos).all()


@pytest.mark.parametrize(("league", "kept"), [(True, (0.21, 0.25)), (False, (0.5, 1.0))])
def test_the_league_ball_loses_77_percent_of_its_speed_a_second(
    league: bool, kept: tuple[float, float]
) -> None:
    """``use_league_ball`` (for ``hlvs referee test``): Webots' ``Damping { linear 0.77 angular
    0.77 }``, v *= 0.23 ** t, on a ball rolling at 3 m/s; the match ball keeps most of it."""
    from simulator.world.ball import BALL_JOINT, use_league_ball

    world = World.create(field_class="kid", robots=[], seed=1)
    if league:
        use_league_ball(world.model, world.field)
    r = world.field.ball_radius_m
    world.apply(PlaceBall(position=(-3.0, 0.0, r), velocity=(3.0, 0.0, 0.0)))
    adr = int(world.model.joint(BALL_JOINT).dofadr[0])
    world.data.qvel[adr + 4] = 3.0 / r  # rolling, not sliding
    run_steps(world, 125)  # 1 s
    ball = world.snapshot().ball
    assert kept[0] < math.hypot(ball.velocity[0], ball.velocity[1]) / 3.0 < kept[1]


@pytest.mark.parametrize(("league", "speed"), [(True, 1.01), (False, 0.39)])
def test_a_push_moves_the_league_ball_as_webots_moves_its_scaled_ball(
    league: bool, speed: float
) -> None:
    """The league's ball proto scales its Solid by 0.728 and Webots gives ODE 0.728^3 x 0.205 kg
    = 0.0791 kg (``WbSolid::createOdeMass``, ``actualMass = s * s2 * mass``): the league's
    scenarios push it with ``addForce`` for one 8 ms step, 10 N sends it off at 1.01 m/s; the
    match ball (0.205 kg) at 0.39 m/s. Without gravity, so that only the push acts."""
    from simulator.world.ball import BALL_BODY, league_ball_mass_kg, use_league_ball

    world = World.create(field_class="kid", robots=[], seed=1)
    if league:
        use_league_ball(world.model, world.field)
    assert league_ball_mass_kg(world.field) == pytest.approx(0.0791, abs=1e-4)
    body = int(world.model.body(BALL_BODY).id)
    want_mass = 0.0791 if league else 0.205
    assert float(world.model.body_mass[body]) == pytest.approx(want_mass, abs=1e-4)
    world.model.opt.gravity[:] = 0.0
    r = world.field.ball_radius_m
    world.apply(PlaceBall(position=(0.0, 0.0, r + 0.05), velocity=(0.0, 0.0, 0.0)))
    world.data.xfrc_applied[body, 0] = 10.0
    world.step()
    world.data.xfrc_applied[body, 0] = 0.0
    assert world.snapshot().ball.velocity[0] == pytest.approx(speed, rel=0.02)


@pytest.mark.parametrize(("league", "kept"), [(True, (0.73, 0.79)), (False, (0.81, 0.87))])
def test_the_league_world_bounces_the_ball_at_0_76(league: bool, kept: tuple[float, float]) -> None:
    """``use_league_bounce`` (``hlvs referee test``, the league's world): ``bounce 0.76`` of
    hlvs_webots ``worlds/robocup.wbt``, 0.76 of the normal speed back off the grass (and off a
    robot); the match ball keeps 0.84. Without gravity, so that only the contact acts."""
    from simulator.world.ball import use_league_bounce

    world = World.create(field_class="kid", robots=[], seed=1)
    if league:
        use_league_bounce(world.model)
    world.model.opt.gravity[:] = 0.0
    r = world.field.ball_radius_m
    world.apply(PlaceBall(position=(0.0, 0.0, r + 0.01), velocity=(0.0, 0.0, -2.0)))
    run_steps(world, 10)  # 80 ms: down 1 cm, the contact, and away
    vz = world.snapshot().ball.velocity[2]
    assert kept[0] < vz / 2.0 < kept[1], vz


def test_the_league_ball_leaves_a_post_within_about_one_basic_step_as_in_ode() -> None:
    """ODE's contact with a robot or a goal (softCFM 0.001, ERP 0.2: a spring of 25,000 N/m,
    and the bounce's velocity target met in the one 8 ms step that finds the contact) sends
    the ball away in that step; the match ball's contact spring (10,000 m/s^2 per m) held the
    0.0791 kg ball for 32 ms, 1.7 cm deep at 2 m/s, so a ball pushed into a robot's knee
    touched it for four basic steps and reached the other leg. Here (``use_league_contacts``:
    100,000 per m, 0.74 kept) it touches a post at 2 m/s in at most two basic steps, under
    6 mm deep."""
    from simulator.world.ball import BALL_BODY, use_league_ball, use_league_contacts

    world = World.create(field_class="kid", robots=[], seed=1, ball_turf_pair=True)
    use_league_ball(world.model, world.field)
    use_league_contacts(world.model)
    world.model.opt.gravity[:] = 0.0
    r = world.field.ball_radius_m
    world.apply(PlaceBall(position=(4.5 - 0.05 - r - 0.01, 1.35, 0.3), velocity=(2.0, 0.0, 0.0)))
    ball = world.model.body(BALL_BODY).id
    touching, deepest = 0, 0.0
    for _ in range(10):
        world.step()
        depths = [
            c.dist for c in world.data.contact[: world.data.ncon]
            if ball in (world.model.geom_bodyid[c.geom1], world.model.geom_bodyid[c.geom2])
        ]  # fmt: skip
        touching += bool(depths)
        deepest = min([deepest, *depths])
    assert 1 <= touching <= 2 and -0.006 < deepest, (touching, deepest)
    assert world.snapshot().ball.velocity[0] < -1.2  # and away (0.742 of it, damped 80 ms)


@pytest.mark.parametrize(("target", "kept"), [("turf", (0.05, 0.13)), ("post", (0.72, 0.78))])
def test_the_league_test_world_makes_the_ball_s_contacts_as_ode_makes_them(
    target: str, kept: tuple[float, float]
) -> None:
    """``use_league_contacts`` (``hlvs referee test --contacts ode``; hlvs_webots
    ``worlds/robocup.wbt:30-45``): ODE's grass (``bounce 0.76, softCFM 0.05``) sends the
    0.0791 kg ball back at 0 to 0.17 of its normal speed, the spring and damper ODE's ERP and
    CFM make keeps 0.08 (measured here, the speed lost to the ball's damping on the way put
    back); anything else (``bounce 0.76`` at the default softCFM 0.001: a robot, a goal post)
    0.742 in ODE, 0.76 here. Without gravity, so that only the contact acts."""
    from simulator.world.ball import use_league_ball, use_league_contacts

    world = World.create(field_class="kid", robots=[], seed=1, ball_turf_pair=True)
    use_league_ball(world.model, world.field)
    use_league_contacts(world.model)
    world.model.opt.gravity[:] = 0.0
    r = world.field.ball_radius_m
    if target == "turf":
        world.apply(PlaceBall(position=(0.0, 0.0, r + 0.01), velocity=(0.0, 0.0, -2.0)))
    else:  # the right goal's post at (4.5, 1.35), 0.05 m thick
        at = (4.5 - 0.05 - r - 0.01, 1.35, 0.3)
        world.apply(PlaceBall(position=at, velocity=(2.0, 0.0, 0.0)))
    run_steps(world, 10)  # 80 ms: 1 cm, the contact, and away
    velocity = world.snapshot().ball.velocity
    back = velocity[2] if target == "turf" else -velocity[0]
    assert kept[0] < back / 2.0 / 0.23**0.08 < kept[1], velocity
