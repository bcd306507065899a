"""Build a match session: the world, the referee on simulated time and the stub robots.

The match is a real one: the GameController state machine and every automatic-referee rule run
after each step, exactly as in the simulator process. The league's wall-clock waits run on
simulated time (:class:`envs.session.SimClock`) and are short (1 s before the first READY, none
between halves), READY lasts 15 s. Stub robots run the stub robot's controller in-process on the
robot API's sensors, with idealised localisation and ball perception (their pose is known, the
ball is seen when it is in their camera's view, every 96 ms) instead of the camera image.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from contracts import ENVIRONMENT, MatchSpec, PlayerSpec, Pose, TeamSpec, TimingSpec
from envs.randomization import episode_world
from envs.session_spec import SessionSpec, StubSpec
from referee import GameState, Referee, RobotId, TeamColor
from simulator import referee_config
from simulator.world import MOTOR_NAMES, World

STUB_LOOK_PERIOD_MS = 96
WAIT_BEFORE_FIRST_READY_S = ENVIRONMENT.wait_before_first_ready_s


@dataclass(slots=True)
class StubRobot:
    id: RobotId
    controller: Any  # robot.stub.controller.StubController


def _player(number: int, pose: tuple[float, float, float], model: str, keeper: bool) -> PlayerSpec:
    p = Pose(x_m=pose[0], y_m=pose[1], yaw_rad=pose[2])
    return PlayerSpec(
        number=number, model=model, port=0, half_time_pose=p, reentry_pose=p, shootout_pose=p,
        goalkeeper_pose=p, goalkeeper=keeper,
    )  # fmt: skip


def match_spec(spec: SessionSpec, seed: int) -> MatchSpec:
    """The simulator's match spec for a session (ports unused: nothing listens)."""
    teams: dict[str, list[PlayerSpec]] = {"red": [], "blue": []}
    teams[spec.learner_color].append(
        _player(spec.learner_number, spec.learner_pose, spec.model, keeper=False)
    )
    for stub in spec.stubs:
        pose = (stub.x_m, stub.y_m, stub.yaw_rad)
        teams[stub.color].append(_player(stub.number, pose, spec.model, stub.role == "goalie"))
    team_specs = {
        color: TeamSpec(
            color=color,  # type: ignore[arg-type]
            team_id=1 if color == "red" else 2,
            name=f"{color} team",
            players=tuple(sorted(players, key=lambda p: p.number)),
            hosts=(),
        )
        for color, players in teams.items()
    }
    timing = TimingSpec(
        half_duration_s=spec.half_duration_s,
        ready_duration_s=spec.ready_duration_s,
        minimum_play_s=spec.minimum_play_s,
        wait_before_first_ready_real_s=WAIT_BEFORE_FIRST_READY_S,
        half_time_break_real_s=0.0,
    )
    return MatchSpec(
        match_id=f"env-{seed}",
        seed=seed,
        game_type="NORMAL",
        field_class=spec.field_class,  # type: ignore[arg-type]
        side_left="red",
        kickoff="red" if seed % 2 == 0 else "blue",
        red=team_specs["red"],
        blue=team_specs["blue"],
        stepping="lockstep",
        maximum_real_time_factor=0.0,
        physics_dt_s=spec.physics_dt_s,
        timing=timing,
    )


def build_match(
    spec: SessionSpec, *, seed: int, clock: Any
) -> tuple[World, Referee, list[StubRobot]]:
    from robot.motion import SERVO_PID
    from robot.stub import Role, StubController

    mspec = match_spec(spec, seed)
    episode = episode_world(
        look=spec.look, texture_seed=spec.texture_seed, sensors=spec.sensors, seed=seed
    )
    world = World.create(
        field_class=mspec.field_class,
        robots=World.placements_of(mspec),
        seed=seed,
        physics_dt_s=mspec.physics_dt_s,
        texture_seed=episode.texture_seed,
        sensor_model=episode.sensor_model,
        camera_model=episode.camera_model,
    )
    config = referee_config(mspec)
    # the robots start on the field (their half-time poses are their episode's start poses)
    config = replace(config, timing=replace(config.timing, status_period_real_s=1e9),
                     start_positions_checked=False)  # fmt: skip
    referee = Referee(config=config, clock=clock)
    stubs = []
    for stub in spec.stubs:
        controller = StubController(
            role=Role(stub.role) if stub.role != "idle" else Role.STRIKER,
            start_pose=Pose(x_m=stub.x_m, y_m=stub.y_m, yaw_rad=stub.yaw_rad),
            model=spec.model,
            field_class=spec.field_class,
            home=(stub.x_m, stub.y_m) if stub.role == "defender" else None,
        )
        stubs.append(StubRobot(id=RobotId(TeamColor(stub.color), stub.number),
                               controller=controller))  # fmt: skip
        if stub.role == "idle":
            stubs.pop()
            continue
        for name in world.motor_names(stubs[-1].id):  # the gains the stub's motions expect
            world.set_motor_pid(stubs[-1].id, name, *SERVO_PID)
    return world, referee, stubs


def _team_pose(x: float, y: float, yaw: float, attack_sign: float) -> tuple[float, float, float]:
    if attack_sign > 0:
        return x, y, yaw
    return -x, -y, math.atan2(math.sin(yaw + math.pi), math.cos(yaw + math.pi))


def tick_stub(stub: StubRobot, world: World, referee: Referee, range_m: float) -> None:
    """One control step of a stub robot: sensors in, motor targets out."""
    from envs.perception import CameraView
    from robot.stub import GameInfo, Sensors

    gc = referee.gc
    robot = world.index.by_id[stub.id]
    if world.removed[robot.number]:
        return
    attack = 1.0 if referee.left_team is stub.id.team else -1.0
    data = world.data
    r = robot.root_qpos
    w, qx, qy, qz = data.qpos[r + 3 : r + 7]
    yaw = math.atan2(2 * (w * qz + qx * qy), 1 - 2 * (qy * qy + qz * qz))
    x, y, heading = _team_pose(float(data.qpos[r]), float(data.qpos[r + 1]), yaw, attack)
    pose = Pose(x_m=x, y_m=y, yaw_rad=heading)
    controller = stub.controller
    controller.world.reset_pose(pose)
    now = world.sim_time_ms
    if now % STUB_LOOK_PERIOD_MS == 0:
        cam = robot.camera
        spec = robot.model.camera
        view = CameraView.from_mujoco(
            data.cam_xpos[cam], data.cam_xmat[cam], hfov_rad=spec.fov_rad,
            aspect=spec.width / spec.height, max_range_m=range_m,
        )  # fmt: skip
        q = world.index.ball_qpos
        ball = data.qpos[q : q + 3]
        if view.points(np.asarray(ball).reshape(1, 3))[0, 0] > 0:
            bx, by, _ = _team_pose(float(ball[0]), float(ball[1]), 0.0, attack)
            controller.world.see_ball(now, *pose.to_relative(bx, by))
    positions = world.read_position_array(stub.id)
    sensors = Sensors(
        time_ms=now,
        joints=dict(zip(MOTOR_NAMES, positions.tolist(), strict=True)),
        accel=world.read_accelerometer(stub.id),
        gyro=world.read_gyro(stub.id),
    )
    state = gc.state
    game = GameInfo(
        phase=state,
        penalised=stub.id in gc.penalised(),
        our_kick_off=gc.kickoff_team is stub.id.team,
        first_half=gc.half == 1,
        ball_free_in_s=float(gc.secondary_time) if state is GameState.PLAYING else 0.0,
    )
    targets = controller.tick(sensors, game)
    if targets:
        world.set_motor_positions(stub.id, list(targets), list(targets.values()))


def default_stubs() -> tuple[StubSpec, ...]:
    """The opponents of the default match environment: a blue goalie and a blue striker."""
    return (
        StubSpec(color="blue", number=1, role="goalie", x_m=-4.0, y_m=0.0, yaw_rad=0.0),
        StubSpec(color="blue", number=2, role="striker", x_m=-1.0, y_m=1.0, yaw_rad=0.0),
    )
