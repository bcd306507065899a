"""One observation of a session: the learning robot's sensors plus what rewards need.

``sensors`` holds what the robot API would report, flat (float64): the joint angles in
``MOTOR_NAMES`` order, accelerometer (x, y, z, m/s^2), gyro (x, y, z, rad/s) and the eight sole
force sensors (N) in ``FORCE_SENSORS`` order. ``truth`` is ground truth for rewards and
statistics (never part of the observation): ball position and velocity, the learning robot's
torso x, y, yaw, the z component of its torso's up axis, its torso height and its right toe
(x, y, z of the front centre of the right sole; NaN for a robot model without the project's
sole geoms).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TypedDict

import numpy as np
import numpy.typing as npt

from contracts import EventRecord
from simulator.world import FORCE_SENSORS, MOTOR_NAMES

FloatArray = npt.NDArray[np.float64]

SENSOR_NAMES: tuple[str, ...] = (
    *(f"{name}S" for name in MOTOR_NAMES),
    "Accelerometer",
    "Gyro",
    *FORCE_SENSORS,
)
N_JOINTS = len(MOTOR_NAMES)
SENSOR_SIZE = N_JOINTS + 3 + 3 + len(FORCE_SENSORS)
JOINTS = slice(0, N_JOINTS)
ACCEL = slice(N_JOINTS, N_JOINTS + 3)
GYRO = slice(N_JOINTS + 3, N_JOINTS + 6)
FORCES = slice(N_JOINTS + 6, SENSOR_SIZE)

TRUTH_SIZE = 14
BALL_POS = slice(0, 3)
BALL_VEL = slice(3, 6)
ROBOT_XY = slice(6, 8)
ROBOT_YAW = 8
UP_Z = 9
TORSO_Z = 10
TOE_R = slice(11, 14)
RIGHT_SOLE = "foot:sole_R"  # the robot's geom whose front edge is TOE_R (front centre, mid-plate)


class GameView(TypedDict, total=False):
    """The learning robot's view of the game (match sessions; see envs.session.game_view, which
    fills every key). Readers take a frame without one as an empty view."""

    state: str  # GameController state name
    secondary_state: str
    score_own: int
    score_opponent: int
    secs_remaining: float
    half: int
    penalised: bool
    own_kickoff: bool
    attack_sign: float  # +1.0 when the robot's team attacks towards +x
    finished: bool


class FrameWire(TypedDict):
    """A frame on the trainer channel (the sensors and the image travel apart)."""

    sim_time_ms: int
    truth: list[float]
    perception: dict[str, list[float]] | None
    game: GameView | None
    events: list[EventRecord]


@dataclass(slots=True, kw_only=True)
class Frame:
    sim_time_ms: int
    sensors: FloatArray
    truth: FloatArray
    image: npt.NDArray[np.uint8] | None = None  # height x width x 3, B G R (as the robot API)
    perception: dict[str, npt.NDArray[np.float64]] | None = None
    game: GameView | None = None  # match sessions: see envs.session.game_view
    events: list[EventRecord] = field(default_factory=list)

    def to_wire(self) -> FrameWire:
        """Plain data for the trainer channel (arrays as lists)."""
        return {
            "sim_time_ms": self.sim_time_ms,
            "truth": self.truth.tolist(),
            "perception": None
            if self.perception is None
            else {k: v.tolist() for k, v in self.perception.items()},
            "game": self.game,
            "events": self.events,
        }

    @classmethod
    def from_wire(
        cls, data: FrameWire, sensors: FloatArray, image: npt.NDArray[np.uint8] | None
    ) -> Frame:
        perception = data.get("perception")
        return cls(
            sim_time_ms=int(data["sim_time_ms"]),
            sensors=sensors,
            truth=np.asarray(data["truth"], dtype=np.float64),
            image=image,
            perception=None
            if perception is None
            else {k: np.asarray(v, dtype=np.float64) for k, v in perception.items()},
            game=data.get("game"),
            events=list(data.get("events") or []),
        )
