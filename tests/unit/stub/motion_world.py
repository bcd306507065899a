"""A one-robot MuJoCo world for the motion tests (the real world of simulator.world)."""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import numpy as np

from contracts.ids import RobotId, TeamColor
from referee.snapshot import PlaceBall
from robot.geometry import KID_GEOMETRY
from robot.motion import SERVO_PID, standing_posture
from robot.stub.controller import Sensors
from simulator.world import RobotPlacement, World
from simulator.world.robots import RobotModel, robot_model
from simulator.world.types import FieldClassName
from testkit.stub_world import sense

RED1 = RobotId(TeamColor.RED, 1)


class OneRobot:
    def __init__(
        self,
        *,
        x_m: float = 0.0,
        y_m: float = 0.0,
        yaw_rad: float = 0.0,
        model: str = "kid-default",
        seed: int = 3,
    ) -> None:
        built_in = robot_model(model)
        assert isinstance(built_in, RobotModel)
        self.model = model
        self.scale = built_in.geometry.thigh_m / KID_GEOMETRY.thigh_m
        field_class: FieldClassName = "kid" if built_in.field_class == "kid" else "adult"
        self.world = World.create(
            field_class=field_class,
            robots=[RobotPlacement(id=RED1, model=model, x_m=x_m, y_m=y_m, yaw_rad=yaw_rad)],
            seed=seed,
        )
        for name in self.world.motor_names(RED1):
            self.world.set_motor_pid(RED1, name, *SERVO_PID)
        self.torso = self.world.model.body("red_1/torso").id
        self.ball = self.world.model.body("ball").id
        self.place_ball(x_m + 3.0, y_m + 3.0)  # out of the way

    def command(self, targets: dict[str, float]) -> None:
        for name, value in targets.items():
            self.world.set_motor_position(RED1, name, value)

    def stand(self, seconds: float = 1.0) -> None:
        posture = standing_posture(self.model)
        for _ in range(int(seconds / 0.008)):
            self.command(posture)
            self.world.step()

    def rise(self, seconds: float = 1.0) -> None:
        """Ease from the joints as they are into the standing posture over ``seconds``, then
        hold it half a second (the adult robot placed with straight legs falls over when its
        knees are bent at the servos' full speed)."""
        from robot.motion.keyframes import Keyframe, KeyframeMotion

        posture = standing_posture(self.model)
        motion = KeyframeMotion([Keyframe(duration_s=seconds, targets=posture)], start=self.joints)
        self.run(seconds, lambda: motion.step(0.008), stop_on_fall=False)
        self.run(0.5, lambda: posture, stop_on_fall=False)

    def run(
        self, seconds: float, targets: Callable[[], dict[str, float]], *, stop_on_fall: bool = True
    ) -> bool:
        """Steps ``seconds``; False as soon as the robot falls (unless ``stop_on_fall`` is off)."""
        for _ in range(int(seconds / 0.008)):
            self.command(targets())
            self.world.step()
            if stop_on_fall and self.up < 0.5:
                return False
        return True

    @property
    def accel(self) -> tuple[float, float, float]:
        return self.world.read_accelerometer(RED1)

    @property
    def gyro(self) -> tuple[float, float, float]:
        return self.world.read_gyro(RED1)

    @property
    def position(self) -> np.ndarray:
        return np.array(self.world.data.xpos[self.torso], dtype=np.float64)

    @property
    def yaw(self) -> float:
        m = self.world.data.xmat[self.torso].reshape(3, 3)
        return math.atan2(m[1, 0], m[0, 0])

    @property
    def up(self) -> float:
        return float(self.world.data.xmat[self.torso].reshape(3, 3)[2, 2])

    @property
    def ball_position(self) -> np.ndarray:
        return np.array(self.world.data.xpos[self.ball], dtype=np.float64)

    def place_ball(self, x_m: float, y_m: float) -> None:
        """The ball at rest on the grass at (``x_m``, ``y_m``)."""
        self.world.apply(PlaceBall(position=(x_m, y_m, self.world.field.ball_radius_m)))

    def sole(self, side: str) -> np.ndarray:
        geom = self.world.model.geom(f"red_1/foot:sole_{side}").id
        return np.array(self.world.data.geom_xpos[geom], dtype=np.float64)

    def lay_down(self, side: str, *, settle_s: float = 1.2) -> None:
        """Put the robot on its front or back (torso 0.15 m up on the kid, scaled with the model,
        falling flat), joints standing."""
        import mujoco

        adr = self.world.model.joint("red_1/root").qposadr[0]
        angle = math.pi / 2 if side == "front" else -math.pi / 2
        yaw = self.yaw
        qz = np.array([math.cos(yaw / 2), 0.0, 0.0, math.sin(yaw / 2)])
        qy = np.array([math.cos(angle / 2), 0.0, math.sin(angle / 2), 0.0])
        quat = np.zeros(4)
        mujoco.mju_mulQuat(quat, qz, qy)
        self.world.data.qpos[adr + 2] = 0.15 * self.scale
        self.world.data.qpos[adr + 3 : adr + 7] = quat
        self.world.data.qvel[:] = 0.0
        mujoco.mj_forward(self.world.model, self.world.data)
        self.stand(settle_s)

    def sensors(self, camera: Any | None = None) -> Sensors:
        """What the controller reads now, as in a match (the image every 96 ms with a camera)."""
        sensed: Sensors = sense(self.world, RED1, camera)
        return sensed

    @property
    def joints(self) -> dict[str, float]:
        return {name[:-1]: value for name, value in self.world.read_positions(RED1).items()}
