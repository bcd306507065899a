"""The contract between the simulator and the referee: plain data, no MuJoCo types.

The simulator builds one :class:`WorldSnapshot` per basic step (8 ms of simulated time) and hands
it to the referee; the referee answers with :data:`WorldCommand` values that the simulator
applies before the next step. Frame: see :mod:`contracts.field`. Angles in radians.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field
from enum import Enum

from contracts import EventRecord, Pose, RobotId, TeamColor

Vec3 = tuple[float, float, float]
Vec2 = tuple[float, float]


class BodyPart(str, Enum):  # noqa: UP042
    """Tags of robot solids, as the HLVS referee's ``[hand]``, ``[foot]``, ``[arm]`` suffixes."""

    FOOT = "foot"
    HAND = "hand"
    ARM = "arm"
    HEAD = "head"
    TORSO = "torso"
    LEG = "leg"


@dataclass(frozen=True, slots=True, kw_only=True)
class BallState:
    position: Vec3
    velocity: Vec3


@dataclass(frozen=True, slots=True, kw_only=True)
class RobotState:
    """One robot at one instant.

    ``ground_contacts`` and ``ball_contacts`` hold the body parts that touch the ground (turf) or
    the ball in this step; ``robot_contacts`` the other robots touched. ``hull_points`` are the XY
    positions of the hand and foot solids (for the ball-holding rule): hands left, right, then
    feet left, right. ``sole_outline`` is the rectangle the left foot's solids cover in the
    foot's frame (x back, x front, y right, y left, m; the right foot mirrors it), from which
    :meth:`sole_corners` places the soles' corners on the ground. ``fallen`` is the
    simulator's judgement that a non-foot part touches the ground or the torso is tilted more
    than 60 degrees.
    """

    id: RobotId
    position: Vec3  # torso (root body) position
    yaw_rad: float
    center_of_mass: Vec3
    velocity: Vec3  # of the centre of mass, m/s
    ground_contacts: frozenset[BodyPart] = frozenset()
    ball_contacts: frozenset[BodyPart] = frozenset()
    robot_contacts: frozenset[RobotId] = frozenset()
    hull_points: tuple[Vec2, ...] = ()
    sole_outline: tuple[float, float, float, float] = (0.0, 0.0, 0.0, 0.0)
    fallen: bool = False
    limp: bool = False  # penalised: actuators off, sensors on
    removed: bool = False  # red card: out of the world

    def sole_corners(self) -> tuple[Vec2, ...]:
        """The XY corners of both soles (four each): a foot's ``sole_outline`` around its
        position in ``hull_points``, turned by the robot's yaw (a standing robot's feet point
        where its torso does); none without the feet's positions."""
        if len(self.hull_points) < 4:
            return ()
        back, front, right, left = self.sole_outline
        c, s = math.cos(self.yaw_rad), math.sin(self.yaw_rad)
        corners = []
        for (fx, fy), sides in zip(self.hull_points[2:4], ((right, left), (-left, -right)),
                                   strict=True):  # fmt: skip
            for dx in (back, front):
                for dy in sides:
                    corners.append((fx + c * dx - s * dy, fy + s * dx + c * dy))
        return tuple(corners)

    @property
    def touches_ground_outside_feet(self) -> bool:
        return any(part is not BodyPart.FOOT for part in self.ground_contacts)


@dataclass(frozen=True, slots=True, kw_only=True)
class WorldSnapshot:
    sim_time_ms: int
    ball: BallState
    robots: tuple[RobotState, ...]
    last_ball_toucher: RobotId | None = None
    last_ball_touch_ms: int | None = None

    def robot(self, robot_id: RobotId) -> RobotState:
        for robot in self.robots:
            if robot.id == robot_id:
                return robot
        raise KeyError(str(robot_id))

    @property
    def sim_time_s(self) -> float:
        return self.sim_time_ms / 1000.0


# --- commands the referee gives the world ---------------------------------------------------


@dataclass(frozen=True, slots=True, kw_only=True)
class PlaceBall:
    position: Vec3
    velocity: Vec3 = (0.0, 0.0, 0.0)


@dataclass(frozen=True, slots=True, kw_only=True)
class TeleportRobot:
    """Move a robot to a pose (torso x, y on the ground, standing height chosen by the world),
    reset its joints to the standing posture and zero its velocities."""

    robot: RobotId
    pose: Pose


@dataclass(frozen=True, slots=True, kw_only=True)
class SetLimp:
    """Penalised robots are limp (actuators off, sensors on); ``limp=False`` restores control."""

    robot: RobotId
    limp: bool


@dataclass(frozen=True, slots=True, kw_only=True)
class RemoveRobot:
    """Red card: the robot leaves the world (parked far outside the field, physics off)."""

    robot: RobotId


@dataclass(frozen=True, slots=True, kw_only=True)
class RestoreRobot:
    """Bring a removed robot back at a pose."""

    robot: RobotId
    pose: Pose


WorldCommand = PlaceBall | TeleportRobot | SetLimp | RemoveRobot | RestoreRobot


@dataclass(frozen=True, slots=True, kw_only=True)
class RefereeEvent:
    """One line of the machine log (JSON lines): time, type, team, player, reason, placement."""

    sim_time_ms: int
    type: str  # e.g. "goal", "ball_out", "penalty", "state", "dropped_ball", "card", "kickoff"
    team: TeamColor | None = None
    player: int | None = None
    reason: str = ""
    placement: Vec3 | None = None
    details: dict[str, object] = field(default_factory=dict)

    def to_record(self) -> EventRecord:
        """The event as the replay, the telemetry and the events log carry it (a copy: nothing
        shared with this event)."""
        data = asdict(self)
        return {
            "sim_time_ms": data["sim_time_ms"],
            "type": data["type"],
            "team": self.team.value if self.team is not None else None,
            "player": data["player"],
            "reason": data["reason"],
            "placement": data["placement"],
            "details": data["details"],
        }
