"""The soccer world: MuJoCo model and state, stepping, snapshots, referee commands, devices.

Order of work in one basic step (``step_ms``, default 8 ms = 4 physics substeps of 2 ms):
motors write ``ctrl`` (velocity-limited targets, torque mode, limp), MuJoCo steps (sensors are
evaluated in the last substep only, since they are read once per basic step), removed robots
are held at their parking spots, divergence is checked (policy ``fail`` raises
:class:`PhysicsDivergence`, ``reset_robot`` restores the previous state and resets the offending
robot), the sensors' noisy readings are drawn (unless the sensor model is ideal:
:mod:`simulator.world.sensor_noise`) and the last ball toucher is updated. The robot API's
reads see those readings; the snapshot (referee, replay, telemetry) the true state.

:meth:`World.snapshot` is built by :class:`simulator.world.snapshot.SnapshotBuilder`, which
precomputes what it can so that a snapshot of eight robots costs about 40 us of the 8 ms step's
roughly 900 us of CPU (its module says how and what was measured).
"""

from __future__ import annotations

import logging
import math
import weakref
from collections.abc import Sequence

import mujoco
import numpy as np

from contracts import FieldGeometry, MatchSpec, RobotId, TeamColor, field_for
from referee import WorldCommand, WorldSnapshot
from simulator.errors import PhysicsDivergence
from simulator.world import commands
from simulator.world.camera_model import CameraModel
from simulator.world.devices import DeviceAccess
from simulator.world.divergence import DivergenceWatch, route_mujoco_warnings
from simulator.world.flat import FlatData
from simulator.world.indices import build_index
from simulator.world.look import look_for
from simulator.world.motors import MotorBank
from simulator.world.prefetch import PositionStage
from simulator.world.robots import robot_model
from simulator.world.scene import compile_scene
from simulator.world.sensor_noise import SensorModel, SensorNoise
from simulator.world.snapshot import BallToucher, SnapshotBuilder
from simulator.world.types import DivergencePolicy, FieldClassName, RobotPlacement

logger = logging.getLogger(__name__)

_SENSOR_OFF = int(mujoco.mjtDisableBit.mjDSBL_SENSOR)


class World(DeviceAccess):
    """Create with :meth:`create` or :meth:`from_spec`; step, snapshot, apply commands."""

    def __init__(
        self,
        *,
        field: FieldGeometry,
        placements: Sequence[RobotPlacement],
        seed: int,
        physics_dt_s: float,
        step_ms: int,
        divergence_policy: DivergencePolicy,
        initial_joint_noise_rad: float,
        texture_seed: int | None = None,
        sensor_model: SensorModel | None = None,
        camera_model: CameraModel | None = None,
        ball_turf_pair: bool = False,
    ) -> None:
        substeps = _checked_substeps(physics_dt_s, step_ms, divergence_policy, placements)
        route_mujoco_warnings()
        ids = [p.id for p in placements]
        self.field = field
        self.placements = tuple(placements)
        self.seed = seed
        self.physics_dt_s = physics_dt_s
        self.step_ms = step_ms
        self.substeps = int(round(substeps))
        self.divergence_policy: DivergencePolicy = divergence_policy
        self.rng = np.random.default_rng(seed)
        self.look = look_for(seed if texture_seed is None else texture_seed)
        self.model = compile_scene(
            field,
            placements,
            physics_dt_s=physics_dt_s,
            look=self.look,
            ball_turf_pair=ball_turf_pair,
        )
        self.camera_model = camera_model if camera_model is not None else CameraModel.ideal()
        self.data = mujoco.MjData(self.model)
        self._opt = self.model.opt  # a view of the model's options (one wrapper, not one a step)
        self.index = build_index(self.model, placements)
        self.robot_ids: tuple[RobotId, ...] = tuple(ids)
        self.motors = MotorBank(
            self.model,
            [
                (int(robot.actuators[slot]), spec)
                for robot in self.index.robots
                for slot, spec in enumerate(robot.model.motors)
            ],
            step_ms / 1000.0,
        )
        self.limp = [False] * len(ids)
        self.removed = [False] * len(ids)
        self.parked_qpos: dict[int, np.ndarray] = {}
        self.sim_time_ms = 0
        self.last_ball_toucher: RobotId | None = None
        self.last_ball_touch_ms: int | None = None
        self._stand_robots(initial_joint_noise_rad)
        mujoco.mj_forward(self.model, self.data)
        self._sensor_span = FlatData(self.data, ("qpos", "sensordata"))
        self.sensor_model = sensor_model if sensor_model is not None else SensorModel.ideal()
        self.sensor_noise = self._sensor_noise(seed)
        self._readings = (
            self._sensor_span.values if self.sensor_noise is None else self.sensor_noise.values
        )
        self._watch = DivergenceWatch(self.data)
        self._snapshots = SnapshotBuilder(self.data, self.index, self.robot_ids)
        self._ball_toucher = BallToucher(self.data, self.index)
        self._saved = self._save()
        self._stage: PositionStage | None = None

    def _stand_robots(self, initial_joint_noise_rad: float) -> None:
        """Every robot's joints and servo targets in its standing pose, each joint moved by up
        to ``initial_joint_noise_rad`` drawn from the world's generator (robot by robot)."""
        for robot in self.index.robots:
            pose = np.asarray(robot.model.standing_pose_rad, dtype=np.float64)
            if initial_joint_noise_rad > 0:
                pose = pose + self.rng.uniform(
                    -initial_joint_noise_rad, initial_joint_noise_rad, size=robot.motor_qpos.size
                )
            if pose.any():
                self.data.qpos[robot.motor_qpos] = pose
                self.motors.hold(robot.actuators, pose)

    def _sensor_noise(self, seed: int) -> SensorNoise | None:
        """The noisy readings of :attr:`sensor_model`; None when it is ideal."""
        if not self.sensor_model.enabled:
            return None
        return SensorNoise(
            model=self.sensor_model,
            flat=self._sensor_span,
            index=self.index,
            encoder_resolution_rad=np.array(
                [m.encoder_resolution_rad for r in self.index.robots for m in r.model.motors]
            ),
            seed=seed,
            step_s=self.step_ms / 1000.0,
        )

    @classmethod
    def create(
        cls,
        *,
        field_class: FieldClassName,
        robots: Sequence[RobotPlacement],
        seed: int,
        physics_dt_s: float = 0.002,
        step_ms: int = 8,
        divergence_policy: DivergencePolicy = "fail",
        initial_joint_noise_rad: float = 0.0,
        texture_seed: int | None = None,
        sensor_model: SensorModel | None = None,
        camera_model: CameraModel | None = None,
        ball_turf_pair: bool = False,
    ) -> World:
        """A world on the ``field_class`` pitch with ``robots`` standing at their poses (world
        frame), the ball on the centre spot. Unknown model names raise UnknownModelError.
        ``ball_turf_pair``: the ball's contact with the turf is an explicit pair of its own
        parameters (:data:`simulator.world.ball.BALL_TURF_PAIR`), for the league's test world.

        The look comes from ``texture_seed`` (default: ``seed``); sensors and cameras are ideal
        unless ``sensor_model`` / ``camera_model`` say otherwise (:meth:`from_spec` gives a
        match the league's)."""
        for placement in robots:
            robot_model(placement.model)
        return cls(
            field=field_for(field_class),
            placements=robots,
            seed=seed,
            physics_dt_s=physics_dt_s,
            step_ms=step_ms,
            divergence_policy=divergence_policy,
            initial_joint_noise_rad=initial_joint_noise_rad,
            texture_seed=texture_seed,
            sensor_model=sensor_model,
            camera_model=camera_model,
            ball_turf_pair=ball_turf_pair,
        )

    @staticmethod
    def placements_of(spec: MatchSpec) -> list[RobotPlacement]:
        """Every player of both teams at its ``half_time_pose``; the team playing on the right
        (not ``spec.side_left``) is mirrored (:meth:`contracts.geometry.Pose.mirrored`)."""
        placements = []
        for color in (TeamColor.RED, TeamColor.BLUE):
            team = spec.red if color is TeamColor.RED else spec.blue
            left = spec.side_left == color.value
            for player in team.players:
                pose = player.half_time_pose.on_side(left=left)
                placements.append(
                    RobotPlacement(
                        id=RobotId(color, player.number),
                        model=player.model,
                        x_m=pose.x_m,
                        y_m=pose.y_m,
                        yaw_rad=pose.yaw_rad,
                    )
                )
        return placements

    @classmethod
    def from_spec(cls, spec: MatchSpec, *, divergence_policy: DivergencePolicy = "fail") -> World:
        """The world of a match: :meth:`placements_of` the spec, its look (``texture_seed``)
        and its sensors (``sensors``: the league's models unless ``"ideal"``)."""
        return cls.create(
            field_class=spec.field_class,
            robots=World.placements_of(spec),
            seed=spec.seed,
            physics_dt_s=spec.physics_dt_s,
            divergence_policy=divergence_policy,
            texture_seed=spec.texture_seed,
            sensor_model=SensorModel.ideal() if spec.sensors == "ideal" else SensorModel(),
            camera_model=(
                CameraModel.ideal()
                if spec.sensors == "ideal"
                else CameraModel.league(spec.seed, motion_blur=spec.camera_motion_blur)
            ),
        )

    # --- stepping ------------------------------------------------------------------------------

    def prefetch(self, *, inline: bool = False) -> None:
        """Begin the next step's first ``mj_step1`` on a worker thread while the caller waits
        (lockstep, for its clients' answers); :meth:`step` finishes it. Nothing but device
        readings and motor targets may be used until then (:meth:`snapshot` and :meth:`apply`
        finish it first). Only with two substeps or more: the first runs without sensors, so
        the readings the robots are sent stay as they are (:mod:`simulator.world.prefetch`).
        ``inline``: computed now on the calling thread (while another thread does the
        waiting: plain lockstep's exchange thread)."""
        if self.substeps < 2:
            return
        if self._stage is None or self._stage.inline != inline:
            if self._stage is not None:
                self._stage.close()
            self._stage = PositionStage(self.model, self.data, inline=inline)
            weakref.finalize(self, self._stage.close)
        self._opt.disableflags |= _SENSOR_OFF
        self._stage.start()

    def _settle(self) -> bool:
        """Finish a prefetched stage (and turn the sensors back on); True when the data holds
        ``mj_step1`` of the state."""
        if self._stage is None:
            return False
        done = self._stage.finish()
        self._opt.disableflags &= ~_SENSOR_OFF
        return done

    def step(self) -> None:
        """Advance one basic step (``step_ms`` of simulated time)."""
        prefetched = self._settle()
        if self.divergence_policy == "reset_robot":
            self._saved = self._save()
        self.motors.apply(self.data)
        if self.substeps > 1:
            # Sensors are read once per basic step: skip them in all but the last substep.
            opt = self._opt
            opt.disableflags |= _SENSOR_OFF
            rest = self.substeps - 1
            if prefetched:  # the first substep's mj_step1 is done: its mj_step2 (the actuation)
                mujoco.mj_step2(self.model, self.data)
                rest -= 1
            if rest:
                mujoco.mj_step(self.model, self.data, nstep=rest)
            opt.disableflags &= ~_SENSOR_OFF
        mujoco.mj_step(self.model, self.data)
        if self.parked_qpos:
            commands.hold_parked(self)
        self.sim_time_ms += self.step_ms
        if self.sensor_noise is not None:
            self.sensor_noise.update()
        divergence = self._watch.check(self.data)
        if divergence is not None:
            self._diverged(divergence.text(self._dof_name(divergence.info)), divergence.info)
        toucher = self._ball_toucher()
        if toucher >= 0:
            self.last_ball_toucher = self.robot_ids[toucher]
            self.last_ball_touch_ms = self.sim_time_ms

    def snapshot(self) -> WorldSnapshot:
        self._settle()
        return self._snapshots.build(
            sim_time_ms=self.sim_time_ms,
            limp=self.limp,
            removed=self.removed,
            last_toucher=self.last_ball_toucher,
            last_touch_ms=self.last_ball_touch_ms,
        )

    def apply(self, command: WorldCommand) -> None:
        """Apply a referee command now (before the next step)."""
        self._settle()
        commands.apply(self, command)

    # --- divergence ----------------------------------------------------------------------------

    def _save(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, float]:
        d = self.data
        return d.qpos.copy(), d.qvel.copy(), d.qacc_warmstart.copy(), float(d.time)

    def _dof_name(self, dof: int) -> str:
        if 0 <= dof < self.model.nv:
            joint = self.model.joint(int(self.model.dof_jntid[dof])).name
            return f"DOF {dof} (joint {joint!r})"
        return f"DOF {dof}"

    def _diverged(self, text: str, dof: int) -> None:
        if self.divergence_policy == "fail":
            raise PhysicsDivergence(sim_time_ms=self.sim_time_ms, warning=text, policy="fail")
        qpos, qvel, warm, time = self._saved
        self.data.qpos[:] = qpos
        self.data.qvel[:] = qvel
        self.data.qacc_warmstart[:] = warm
        self.data.time = time
        self.motors.invalidate()
        offender = int(self.index.dof_robot[dof]) if 0 <= dof < self.model.nv else -1
        if offender < 0:
            speeds = [
                float(np.abs(qvel[r.dof_range[0] : r.dof_range[1]]).max())
                for r in self.index.robots
            ]
            offender = int(np.argmax(speeds)) if speeds else -1
        if offender >= 0 and not self.removed[offender]:
            robot = self.index.robots[offender]
            x, y = (float(v) for v in qpos[robot.root_qpos : robot.root_qpos + 2])
            if not (math.isfinite(x) and math.isfinite(y)):
                x, y = 0.0, 0.0
            commands.teleport(self, robot.number, x, y, self.snapshot().robots[offender].yaw_rad)
            logger.warning(
                "physics diverged at %d ms (%s); reset %s", self.sim_time_ms, text, robot.id
            )
        else:
            commands.place_ball(self, (0.0, 0.0, self.field.ball_radius_m), (0.0, 0.0, 0.0))
            logger.warning("physics diverged at %d ms (%s); reset the ball", self.sim_time_ms, text)
        mujoco.mj_forward(self.model, self.data)


def _checked_substeps(
    physics_dt_s: float,
    step_ms: int,
    divergence_policy: str,
    placements: Sequence[RobotPlacement],
) -> float:
    """Physics substeps in a basic step; raises ValueError when ``step_ms`` is not a multiple
    of ``physics_dt_s``, the divergence policy is unknown or two robots share an id."""
    substeps = step_ms / 1000.0 / physics_dt_s
    if physics_dt_s <= 0 or step_ms <= 0 or abs(substeps - round(substeps)) > 1e-6:
        raise ValueError(
            f"step_ms ({step_ms}) must be a positive multiple of physics_dt_s ({physics_dt_s})"
        )
    if divergence_policy not in ("fail", "reset_robot"):
        raise ValueError(
            f"divergence_policy must be 'fail' or 'reset_robot', not {divergence_policy!r}"
        )
    ids = [p.id for p in placements]
    if len(set(ids)) != len(ids):
        raise ValueError(f"robot ids must be unique: {[str(i) for i in ids]}")
    return substeps
