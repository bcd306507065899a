"""The stub robot process: connect to the robot API, follow the GameController, play.

Entry point of the stub image (``python -m robot.stub striker``). Exits 0 on SIGTERM (after
closing its connection), 2 on a bad command line or environment, 1 when ``crash-after`` fires.
"""

from __future__ import annotations

import functools
import logging
import math
import signal
import sys
import threading
import time
from collections.abc import Callable
from pathlib import Path
from types import FrameType

import numpy as np

from contracts import GameState, Pose
from contracts.robot_api import messages_pb2 as pb
from robot.client import ConnectionClosed, RobotClient, RobotClientError
from robot.client.errors import ReceiveTimeout
from robot.learned import Policy, PolicyFileError, load_policy
from robot.motion import SERVO_PID, kinematics
from robot.stub.behaviour import GameInfo, Role
from robot.stub.controller import Sensors, StubController
from robot.stub.errors import StubConfigError
from robot.stub.faults import MirrorFlooder, fill_logs
from robot.stub.gamestate import GameControllerLink
from robot.stub.options import Behaviour, RobotEnv, StubOptions, parse_args, read_env

logger = logging.getLogger(__name__)

SENSOR_PERIOD_MS = 8
CAMERA_PERIOD_MS = 96
CONNECT_RETRY_S = 0.25  # a refused connect costs nothing; the simulator may boot after us
CONNECT_TIMEOUT_S = 1.0
CRASH_EXIT_CODE = 1


def default_start_pose(robot_id: int) -> Pose:
    """HLVS-style spawn pose in the team's own frame: on the touch line of the own half,
    facing into the field. Pass ``--start-pose`` to match the team file."""
    return Pose(x_m=-3.6 + 0.8 * (robot_id - 1), y_m=-3.2, yaw_rad=math.pi / 2)


class RefereePlacement:
    """The poses the referee puts the robot at, told to the controller as they happen.

    - A new half: the half-time starting pose of the team file, on the side the team now
      plays (sides change, so the mirror image of the previous half's).
    - The end of a penalty during a half: the re-entry point on the touch line of the own
      half, on the side the robot was nearer to.

    A penalty the half's end cuts short is lifted together with the new half's placement (in
    the same GameController packet or in the INITIAL that follows): the robot stands at its
    half-time pose then, not at a re-entry point.
    """

    def __init__(self, start_pose: Pose) -> None:
        self.start_pose = start_pose
        self._first_half: bool | None = None
        self._penalised = False

    def follow(self, controller: StubController, game: GameInfo) -> None:
        new_half = self._first_half is not None and game.first_half != self._first_half
        if new_half:
            before = controller.mirrored
            controller.reset_pose(
                self.start_pose, expect_mirrored=None if before is None else not before
            )
        elif self._penalised and not game.penalised and game.phase is not GameState.INITIAL:
            pose = controller.world.pose
            side = -1.0 if pose.y_m < 0 else 1.0
            reentry = Pose(x_m=-3.0, y_m=3.2 * side, yaw_rad=-side * math.pi / 2)
            controller.reset_pose(reentry, check_side=False)
        self._first_half = game.first_half
        self._penalised = game.penalised


class StubRobot:
    def __init__(self, options: StubOptions, env: RobotEnv, *, gc_data_port: int = 3838,
                 gc_return_port: int = 3939) -> None:  # fmt: skip
        self.options = options
        self.env = env
        self.stop = threading.Event()
        role = {
            Behaviour.STRIKER: Role.STRIKER,
            Behaviour.GOALIE: Role.GOALIE,
            Behaviour.DEFENDER: Role.DEFENDER,
        }.get(options.behaviour, Role.IDLE)
        self.start_pose = (
            Pose(x_m=options.start_pose[0], y_m=options.start_pose[1],
                 yaw_rad=options.start_pose[2])
            if options.start_pose else default_start_pose(env.robot_id)
        )
        self.controller = StubController(
            role=role,
            start_pose=self.start_pose,
            model=options.model,
            field_class=options.field,
            detect_side=role is not Role.IDLE,
            home=options.home,
            kick_policy=_kick_policy(options),
        )
        self.gc = GameControllerLink(
            team_color=env.team_color,
            player=env.robot_id,
            gamecontroller_ip=env.gamecontroller_ip,
            data_port=gc_data_port,
            return_port=gc_return_port,
        )
        self._motors = kinematics(options.model).motor_names
        self._servo_pid = SERVO_PID  # the gains last sent
        self._threads: list[threading.Thread] = []
        self._started = time.monotonic()
        self._crashed = False

    # --- lifecycle -------------------------------------------------------------------------------

    def run(self) -> int:
        self.gc.start()
        self._start_faults()
        try:
            while not self.stop.is_set():
                if self._crash_due():
                    return CRASH_EXIT_CODE
                client = self._connect()
                if client is None:
                    return CRASH_EXIT_CODE if self._crashed else 0
                try:
                    code = self._play(client)
                finally:
                    client.close()
                if code is not None:
                    return code
            logger.info("stopping: %s", "signal" if self.stop.is_set() else "done")
            return 0
        finally:
            self.stop.set()
            self.gc.close()
            for thread in self._threads:
                thread.join(timeout=2.0)

    def _crash_due(self) -> bool:
        limit = self.options.crash_after_s
        if self.options.behaviour is Behaviour.CRASH_AFTER and limit is not None:
            if time.monotonic() - self._started >= limit:
                self._crashed = True
                logger.error("crash-after %.1f s: exiting with code %d", limit, CRASH_EXIT_CODE)
                return True
        return False

    def _start_faults(self) -> None:
        behaviour = self.options.behaviour
        if behaviour is Behaviour.FILL_LOGS:
            cap = self.options.fill_cap_bytes
            self._spawn(
                "fill-logs", lambda: fill_logs(self.env.log_dir, cap_bytes=cap, stop=self.stop)
            )
        if behaviour is Behaviour.FLOOD and self.env.mirror_ip:
            flooder = MirrorFlooder(self.env.mirror_ip, port=self.options.mirror_port)
            self._spawn("flood-mirror", lambda: flooder.run(self.stop))

    def _spawn(self, name: str, target: Callable[[], object]) -> None:
        thread = threading.Thread(target=target, name=name, daemon=True)
        thread.start()
        self._threads.append(thread)

    # --- robot API -----------------------------------------------------------------------------

    def _connect(self) -> RobotClient | None:
        address = f"{self.env.simulator_host}:{self.env.simulator_port}"
        attempts = 0
        while not self.stop.is_set():
            if self._crash_due():
                return None
            attempts += 1
            # a short connect: once the simulator's container is gone its address answers
            # nothing, and a stop signal must not wait out a long connect (the grace period)
            client = RobotClient(self.env.simulator_host, self.env.simulator_port, retries=1,
                                 connect_timeout_s=CONNECT_TIMEOUT_S)
            try:
                client.connect()
            except RobotClientError as exc:
                if attempts == 1 or attempts % 10 == 0:
                    logger.warning(
                        "simulator %s not available (attempt %d): %s", address, attempts, exc
                    )
                self.stop.wait(CONNECT_RETRY_S)
                continue
            logger.info("connected to the simulator at %s", address)
            periods = {name + "S": SENSOR_PERIOD_MS for name in self._motors}
            periods.update(Accelerometer=SENSOR_PERIOD_MS, Gyro=SENSOR_PERIOD_MS)
            if self.controller.role is not Role.IDLE:
                periods["Camera"] = CAMERA_PERIOD_MS
            client.enable_many(periods)
            client.set_pids({name: SERVO_PID for name in self._motors})
            self._servo_pid = SERVO_PID
            if self.options.behaviour is Behaviour.FLOOD:
                self._spawn("flood-simulator", functools.partial(self._flood_simulator, client))
            return client
        return None

    def _flood_simulator(self, client: RobotClient) -> None:
        request = pb.ActuatorRequests()
        for _ in range(50):
            for name in self._motors:
                request.motor_positions.add(name=name, position=0.0)
        sent = 0
        ended = "stopped"
        while not self.stop.is_set():
            try:
                client.send(request)
            except (ConnectionClosed, OSError) as exc:
                ended = str(exc)
                break
            sent += 1
        logger.info("flood: sent %d oversized requests to the simulator: %s", sent, ended)

    def _play(self, client: RobotClient) -> int | None:
        """Control loop; returns an exit code, or None to reconnect."""
        placement = RefereePlacement(self.start_pose)
        previous_phase: GameState | None = None
        while not self.stop.is_set():
            if self._crash_due():
                return CRASH_EXIT_CODE
            try:
                measurement, image = _receive_latest(client)
            except ReceiveTimeout:
                continue
            except RobotClientError as exc:
                logger.warning("lost the simulator connection: %s", exc)
                return None
            game = self.gc.info() or GameInfo(phase=GameState.INITIAL)
            placement.follow(self.controller, game)
            targets = self.controller.tick(_sensors(measurement, image), game)
            if self.controller.servo_pid != self._servo_pid:
                # a learned kick plays with the gains it learnt with (robot.stub.learned_kick)
                self._servo_pid = self.controller.servo_pid
                try:
                    client.set_pids({name: self._servo_pid for name in self._motors})
                except ConnectionClosed as exc:
                    logger.warning("lost the simulator connection: %s", exc)
                    return None
            if game.phase is not previous_phase:
                self._log_belief(game.phase)
                previous_phase = game.phase
            if self.options.behaviour is Behaviour.IGNORE_SIGTERM or targets:
                try:
                    client.set_positions(targets)
                except ConnectionClosed as exc:
                    logger.warning("lost the simulator connection: %s", exc)
                    return None
        return 0

    def _log_belief(self, phase: GameState) -> None:
        """Where the robot believes it is when the game state changes (in the frame of its own
        odometry: the team file's, turned by pi when it plays on the mirrored side)."""
        pose = self.controller.world.pose
        logger.info("%s: pose belief (%.2f, %.2f, %.2f)", phase.name, pose.x_m, pose.y_m,
                    pose.yaw_rad)


def _kick_policy(options: StubOptions) -> Policy | None:
    """The learned kick of ``--kick-policy``; a bad file is a configuration error."""
    if options.kick_policy is None:
        return None
    try:
        policy = load_policy(options.kick_policy)
    except PolicyFileError as exc:
        where = "" if exc.field == "/" else f" (at {exc.field})"
        raise StubConfigError(
            field="--kick-policy", value=str(options.kick_policy),
            expected=f"{exc.expected}{where}",
        ) from exc
    logger.info("learned kick %s from %s", policy.skill, options.kick_policy)
    return policy


def _receive_latest(
    client: RobotClient,
) -> tuple[pb.SensorMeasurements, pb.CameraMeasurement | None]:
    """The newest measurement, skipping older ones already waiting (when the simulation runs
    ahead of this controller), and the newest camera image among them."""
    measurement = client.receive(timeout=0.5)
    image = measurement.cameras[-1] if measurement.cameras else None
    while True:
        try:
            newer = client.receive(timeout=0.0005)
        except ReceiveTimeout:
            return measurement, image
        measurement = newer
        if newer.cameras:
            image = newer.cameras[-1]


def _sensors(
    measurement: pb.SensorMeasurements, camera: pb.CameraMeasurement | None = None
) -> Sensors:
    joints = {
        s.name[:-1] if s.name.endswith("S") else s.name: s.value
        for s in measurement.position_sensors
    }
    accel = gyro = None
    for a in measurement.accelerometers:
        accel = (a.value.X, a.value.Y, a.value.Z)
    for g in measurement.gyros:
        gyro = (g.value.X, g.value.Y, g.value.Z)
    image = None
    if camera is not None and len(camera.image) == camera.width * camera.height * 3:
        image = np.frombuffer(camera.image, np.uint8).reshape(camera.height, camera.width, 3)
    return Sensors(time_ms=measurement.time, joints=joints, accel=accel, gyro=gyro, image_bgr=image)


def _setup_logging(env: RobotEnv) -> None:
    fmt = logging.Formatter(
        f"%(asctime)s %(levelname)s {env.team_color}-{env.robot_id} %(name)s: %(message)s"
    )
    root = logging.getLogger()
    root.setLevel(logging.INFO)
    stream = logging.StreamHandler(sys.stderr)
    stream.setFormatter(fmt)
    root.addHandler(stream)
    try:
        env.log_dir.mkdir(parents=True, exist_ok=True)
        path = Path(env.log_dir) / f"stub_{env.team_color}_{env.robot_id}.log"
        handler = logging.FileHandler(path)
    except OSError as exc:
        logger.warning("cannot write the log folder %s: %s", env.log_dir, exc)
        return
    handler.setFormatter(fmt)
    root.addHandler(handler)


def main(argv: list[str]) -> int:
    try:
        options = parse_args(argv)
        env = read_env()
    except StubConfigError as exc:
        print(str(exc), file=sys.stderr)
        return 2
    _setup_logging(env)
    gc_ports = (options.gc_data_port, options.gc_return_port)
    try:
        robot = StubRobot(options, env, gc_data_port=gc_ports[0], gc_return_port=gc_ports[1])
    except StubConfigError as exc:  # a bad --kick-policy file: one line, no traceback
        print(str(exc), file=sys.stderr)
        return 2

    def on_signal(signum: int, frame: FrameType | None) -> None:
        logger.info("received %s", signal.Signals(signum).name)
        robot.stop.set()

    if options.behaviour is Behaviour.IGNORE_SIGTERM:
        signal.signal(signal.SIGTERM, signal.SIG_IGN)
        logger.info("ignoring SIGTERM")
    else:
        signal.signal(signal.SIGTERM, on_signal)
    signal.signal(signal.SIGINT, on_signal)
    logger.info(
        "stub robot %s %d (%s) for simulator %s:%d",
        env.team_color,
        env.robot_id,
        options.behaviour.value,
        env.simulator_host,
        env.simulator_port,
    )
    return robot.run()
