"""A session: the world behind an environment, run in this process.

``reset`` builds a fresh world (and referee) from the session's settings and the reset request,
so an episode depends on nothing but its seed and what the request places; ``step`` applies the
learning robot's motor targets, runs the stub robots' controllers, steps the physics
``steps_per_action`` times (8 ms each) with the referee after every step, and returns a
:class:`envs.frame.Frame`. The trainer operations (:class:`envs.trainer.Trainer`) act between
steps. A remote simulator runs this same class behind its trainer channel.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any, cast

import mujoco
import numpy as np
import numpy.typing as npt

from contracts import Pose, field_for
from envs.errors import EnvStateError, TrainerError
from envs.frame import RIGHT_SOLE, SENSOR_NAMES, Frame, GameView
from envs.perception import CameraView, add_noise, field_segments, goal_post_feet
from envs.randomization import episode_world
from envs.session_spec import ResetRequest, SessionSpec
from referee import GameState, PlaceBall, Referee, RobotId, TeamColor, TeleportRobot
from simulator.world import MOTOR_NAMES, RobotPlacement, World, robot_model

FloatArray = npt.NDArray[np.float64]
STUB_CAMERA_PERIOD_MS = 96


class SimClock:
    """The referee's clock in a session: simulated time, so its waits cost no wall time."""

    def __init__(self) -> None:
        self.world: World | None = None

    def monotonic(self) -> float:
        return 0.0 if self.world is None else self.world.sim_time_ms / 1000.0


class LocalSession:
    def __init__(self, spec: SessionSpec) -> None:
        self.spec = spec
        self.field = field_for(spec.field_class)
        self.learner = RobotId(TeamColor(spec.learner_color), spec.learner_number)
        self.world: World | None = None
        self.referee: Referee | None = None
        self._stubs: list[Any] = []
        self._renderer: Any = None
        self._rng = np.random.default_rng(0)
        self._events_seen = 0
        self._segments = field_segments(self.field)
        self._camera = robot_model(spec.model).camera
        self._closed = False
        self._plan: tuple[World, Any, Any, slice, int, int, int, float] | None = None

    # --- lifecycle ---------------------------------------------------------------------------

    def reset(self, request: ResetRequest) -> Frame:
        if self._closed:
            raise EnvStateError(operation="reset", reason="the session is closed")
        self._release_world()
        self._rng = np.random.default_rng(request.seed)
        if self.spec.referee:
            self._build_match(request)
        else:
            self._build_skill(request)
        return self._frame()

    def close(self) -> None:
        self._release_world()
        self._closed = True

    def _release_world(self) -> None:
        if self._renderer is not None:
            self._renderer.close()
            self._renderer = None
        if self.referee is not None:
            self.referee.close()
            self.referee = None
        self.world = None
        self._stubs = []

    def _build_skill(self, request: ResetRequest) -> None:
        x, y, yaw = request.learner_pose or (0.0, 0.0, 0.0)
        episode = episode_world(
            look=self.spec.look, texture_seed=self.spec.texture_seed, sensors=self.spec.sensors,
            seed=request.seed,
        )  # fmt: skip
        world = World.create(
            field_class=self.spec.field_class,  # type: ignore[arg-type]
            robots=[
                RobotPlacement(id=self.learner, model=self.spec.model, x_m=x, y_m=y, yaw_rad=yaw)
            ],  # fmt: skip
            seed=request.seed,
            physics_dt_s=self.spec.physics_dt_s,
            texture_seed=episode.texture_seed,
            sensor_model=episode.sensor_model,
            camera_model=episode.camera_model,
        )
        bx, by = request.ball_xy or (0.0, 0.0)
        world.apply(PlaceBall(position=(bx, by, self.field.ball_radius_m)))
        self.world = world
        self._start_camera()

    def _build_match(self, request: ResetRequest) -> None:
        from envs.match_setup import build_match

        clock = SimClock()
        world, referee, stubs = build_match(self.spec, seed=request.seed, clock=clock)
        clock.world = world
        self.world, self.referee, self._stubs = world, referee, stubs
        self._events_seen = 0
        for command in referee.step(world.snapshot()):
            world.apply(command)
        self._start_camera()

    def _start_camera(self) -> None:
        if self.spec.camera:
            from simulator.world import CameraRenderer

            assert self.world is not None
            self._renderer = CameraRenderer(self.world, self._camera.width, self._camera.height)

    # --- stepping ----------------------------------------------------------------------------

    def _live_world(self, operation: str) -> World:
        if self.world is None:
            raise EnvStateError(operation=operation, reason="call reset() first")
        return self.world

    def step(self, targets: FloatArray | list[float]) -> Frame:
        world = self._live_world("step")
        world.set_motor_positions(self.learner, MOTOR_NAMES, cast(Sequence[float], targets))
        referee = self.referee
        for _ in range(self.spec.steps_per_action):
            if self._stubs:
                self._tick_stubs(world)
            world.step()
            if referee is not None:
                for command in referee.step(world.snapshot()):
                    world.apply(command)
        return self._frame()

    def _tick_stubs(self, world: World) -> None:
        from envs.match_setup import tick_stub

        assert self.referee is not None
        for stub in self._stubs:
            tick_stub(stub, world, self.referee, self.spec.perception_range_m)

    # --- observation -------------------------------------------------------------------------

    def _frame(self) -> Frame:
        world = self._live_world("observe")
        sensors, truth = self._read(world)
        frame = Frame(sim_time_ms=world.sim_time_ms, sensors=sensors, truth=truth)
        if self._renderer is not None:
            raw = self._renderer.render(self.learner)
            frame.image = np.frombuffer(raw, np.uint8).reshape(
                self._camera.height, self._camera.width, 3
            )
        if self.spec.perception:
            frame.perception = self.perceive(world)
        if self.referee is not None:
            frame.game = game_view(self.referee, self.learner)
            events = self.referee.events
            if self._events_seen < len(events):
                frame.events = [e.to_record() for e in events[self._events_seen :]]
                self._events_seen = len(events)
        return frame

    def truth(self, world: World) -> FloatArray:
        return self._read(world)[1]

    def _read(self, world: World) -> tuple[FloatArray, FloatArray]:
        """The robot API sensors (``SENSOR_NAMES`` order) and the ground truth, in two gathers
        (index arrays computed once per world)."""
        plan = self._plan
        if plan is None or plan[0] is not world:
            plan = self._plan = self._read_plan(world)
        _, qpos_at, sensordata_at, ball_dof, up_z, n, sole, half_length = plan
        data = world.data
        q = data.qpos[qpos_at]
        sensors = np.concatenate((q[:n], data.sensordata[sensordata_at]))
        bx, by, bz, x, y, w, qx, qy, qz, z = q[n:].tolist()
        vx, vy, vz = data.qvel[ball_dof].tolist()
        yaw = math.atan2(2 * (w * qz + qx * qy), 1 - 2 * (qy * qy + qz * qz))
        up = float(data.xmat.reshape(-1)[up_z])
        # the right toe: the front centre of the right sole, along the sole's forward axis
        if sole >= 0:
            forward = data.geom_xmat[sole].reshape(3, 3)[:, 0]
            tx, ty, tz = (data.geom_xpos[sole] + half_length * forward).tolist()
        else:
            tx = ty = tz = math.nan
        return sensors, np.array([bx, by, bz, vx, vy, vz, x, y, yaw, up, z, tx, ty, tz])

    def _read_plan(self, world: World) -> tuple[World, Any, Any, slice, int, int, int, float]:
        index = world.index
        robot = index.by_id[self.learner]
        q, d, r = index.ball_qpos, index.ball_dof, robot.root_qpos
        truth_at = [q, q + 1, q + 2, r, r + 1, r + 3, r + 4, r + 5, r + 6, r + 2]
        qpos_at = np.array([*robot.motor_qpos.tolist(), *truth_at], dtype=np.int64)
        a, g = robot.accelerometer, robot.gyro
        forces = [robot.forces[name] for name in SENSOR_NAMES[len(robot.motor_qpos) + 2 :]]
        sensordata_at = np.array([a, a + 1, a + 2, g, g + 1, g + 2, *forces], dtype=np.int64)
        up_z = robot.torso_body * 9 + 8
        geom = mujoco.mjtObj.mjOBJ_GEOM
        sole = mujoco.mj_name2id(world.model, geom, f"{robot.prefix}/{RIGHT_SOLE}")
        # a robot model without the project's sole (an imported one) has no toe: NaN
        half_length = float(world.model.geom_size[sole][0]) if sole >= 0 else math.nan
        return (world, qpos_at, sensordata_at, slice(d, d + 3), up_z, len(robot.motor_qpos),
                sole, half_length)  # fmt: skip

    def attack_sign(self, color: TeamColor) -> float:
        """+1 when ``color`` attacks the goal at x > 0 now."""
        if self.referee is None:
            return 1.0 if color is TeamColor.RED else -1.0
        return 1.0 if self.referee.left_team is color else -1.0

    def camera_view(self, world: World, robot: RobotId) -> CameraView:
        cam = world.index.by_id[robot].camera
        return CameraView.from_mujoco(
            world.data.cam_xpos[cam], world.data.cam_xmat[cam], hfov_rad=self._camera.fov_rad,
            aspect=self._camera.width / self._camera.height,
            max_range_m=self.spec.perception_range_m,
        )  # fmt: skip

    def perceive(self, world: World) -> dict[str, FloatArray]:
        view = self.camera_view(world, self.learner)
        q = world.index.ball_qpos
        ball = view.points(np.asarray(world.data.qpos[q : q + 3]).reshape(1, 3))
        posts = view.points(goal_post_feet(self.field, self.attack_sign(self.learner.team)))
        lines = view.segments(self._segments)
        others = [r for r in world.index.robots if r.id != self.learner]
        robots = np.zeros((len(others), 5))
        if others:
            torsos = np.array([world.data.xpos[r.torso_body] for r in others])
            robots[:, :4] = view.points(torsos)
            seen = robots[:, 0] > 0
            same = np.array([r.id.team is self.learner.team for r in others])
            robots[:, 4] = np.where(seen & same, 1.0, 0.0)
        noise = self.spec.perception_noise
        add_noise(ball, slice(1, 4), noise, self._rng)
        add_noise(posts, slice(1, 4), noise, self._rng)
        add_noise(lines, slice(1, 7), noise, self._rng)
        add_noise(robots, slice(1, 4), noise, self._rng)
        return {"ball": ball[0], "goal_posts": posts, "lines": lines, "robots": robots}

    # --- trainer operations ------------------------------------------------------------------

    def place_ball(self, x_m: float, y_m: float, vx_m_s: float = 0.0, vy_m_s: float = 0.0) -> None:
        world = self._live_world("place_ball")
        r = self.field.ball_radius_m
        world.apply(PlaceBall(position=(x_m, y_m, r), velocity=(vx_m_s, vy_m_s, 0.0)))

    def place_robot(self, color: str, number: int, x_m: float, y_m: float, yaw_rad: float) -> None:
        world = self._live_world("place_robot")
        robot = RobotId(TeamColor(color), number)
        if robot not in world.index.by_id:
            known = ", ".join(str(r) for r in world.robot_ids)
            raise TrainerError(operation="place_robot", reason=f"no {robot} here ({known})")
        world.apply(TeleportRobot(robot=robot, pose=Pose(x_m=x_m, y_m=y_m, yaw_rad=yaw_rad)))

    def set_game_state(self, state: str) -> None:
        """Put the GameController into ``state`` now (INITIAL, READY, SET, PLAYING, FINISHED),
        as a trainer may, without the transitions a match would take."""
        referee = self._referee("set_game_state")
        try:
            target = GameState[state.upper()]
        except KeyError:
            names = [s.name for s in GameState]
            raise TrainerError(
                operation="set_game_state", reason=f"{state!r} is not one of {names}"
            ) from None
        world = self._live_world("set_game_state")
        for command in referee.force_state(target, world.snapshot()):
            world.apply(command)

    def drop_ball(self, x_m: float = 0.0, y_m: float = 0.0) -> None:
        """A dropped ball at (x, y): the ball is placed there, the game goes to READY with no
        kick-off team (both teams may play the ball after SET)."""
        referee = self._referee("drop_ball")
        self.place_ball(x_m, y_m)
        referee.force_state(GameState.READY, self._live_world("drop_ball").snapshot())
        referee.gc.kickoff_team = None

    def _referee(self, operation: str) -> Referee:
        if self.referee is None:
            raise TrainerError(
                operation=operation, reason="this session runs no referee (a skill session)"
            )
        return self.referee


def game_view(referee: Referee, learner: RobotId) -> GameView:
    """The learning robot's view of the game: state, secondary state, own and opponent score,
    seconds remaining, half, whether it is penalised, whether its team has the kick-off."""
    gc = referee.gc
    own, opp = learner.team, learner.team.opponent
    return {
        "state": gc.state.name,
        "secondary_state": gc.secondary_state.name,
        "score_own": gc.score(own),
        "score_opponent": gc.score(opp),
        "secs_remaining": float(gc.secs_remaining),
        "half": gc.half,
        "penalised": learner in gc.penalised(),
        "own_kickoff": gc.kickoff_team is own,
        "attack_sign": 1.0 if referee.left_team is own else -1.0,
        "finished": referee.finished,
    }
