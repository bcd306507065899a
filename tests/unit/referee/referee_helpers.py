"""Hand-made configurations and snapshots for the referee unit tests."""

from __future__ import annotations

from contracts.geometry import Pose
from contracts.ids import RobotId, TeamColor
from contracts.match_spec import GameType, PlayerSpec, TeamSpec
from referee.config import RefereeConfig, TimingConfig
from referee.snapshot import BallState, BodyPart, RobotState, WorldSnapshot

RED = TeamColor.RED
BLUE = TeamColor.BLUE

FAST_TIMING = TimingConfig(
    half_duration_s=60.0,
    ready_duration_s=5.0,
    set_to_play_s=1.0,
    wait_before_first_ready_real_s=0.0,
    half_time_break_real_s=0.0,
    removal_penalty_s=3.0,
    dropped_ball_s=20.0,
    fallen_s=2.0,
    outside_turf_s=2.0,
    inactive_goalkeeper_s=3.0,
    set_play_phase0_s=0.5,
    set_play_ready_s=1.0,
    set_play_prepare_s=0.5,
    shootout_set_to_play_s=1.0,
    shootout_kick_s=5.0,
    overtime_half_duration_s=30.0,
)


def player(number: int, *, y: float = -3.1) -> PlayerSpec:
    """Poses as if playing on the left: half-time pose on the touch line of the own half."""
    return PlayerSpec(
        number=number,
        model="kid-default",
        port=10000 + number,
        half_time_pose=Pose(x_m=-0.6 - 0.9 * number, y_m=y, yaw_rad=1.57),
        reentry_pose=Pose(x_m=-3.0, y_m=-3.1, yaw_rad=1.57),
        shootout_pose=Pose(x_m=2.75, y_m=0.0, yaw_rad=0.0),
        goalkeeper_pose=Pose(x_m=-4.4, y_m=0.0, yaw_rad=0.0),
        goalkeeper=number == 1,
    )


def make_config(
    *,
    game_type: GameType = GameType.NORMAL,
    players: int = 2,
    side_left: TeamColor = RED,
    kickoff: TeamColor = RED,
    timing: TimingConfig = FAST_TIMING,
    addresses: dict[TeamColor, tuple[str, ...]] | None = None,
) -> RefereeConfig:
    addresses = addresses or {}
    return RefereeConfig(
        red=TeamSpec(
            color="red", team_id=8, name="Red Team", hosts=addresses.get(RED, ()),
            players=tuple(player(n) for n in range(1, players + 1)),
            robot_addresses=addresses.get(RED, ()),
        ),
        blue=TeamSpec(
            color="blue", team_id=25, name="Blue Team", hosts=addresses.get(BLUE, ()),
            players=tuple(player(n) for n in range(1, players + 1)),
            robot_addresses=addresses.get(BLUE, ()),
        ),
        game_type=game_type,
        side_left=side_left,
        kickoff=kickoff,
        timing=timing,
    )


def robot(
    team: TeamColor,
    number: int,
    x: float,
    y: float,
    *,
    fallen: bool = False,
    velocity: tuple[float, float, float] = (0.0, 0.0, 0.0),
    ball_contact: bool = False,
    contacts: tuple[RobotId, ...] = (),
    hull: bool = True,
) -> RobotState:
    hull_points = (
        ((x + 0.05, y + 0.06), (x + 0.05, y - 0.06), (x - 0.05, y + 0.06), (x - 0.05, y - 0.06))
        if hull
        else ()
    )
    return RobotState(
        id=RobotId(team, number),
        position=(x, y, 0.3),
        yaw_rad=0.0,
        center_of_mass=(x, y, 0.25),
        velocity=velocity,
        ball_contacts=frozenset({BodyPart.FOOT}) if ball_contact else frozenset(),
        robot_contacts=frozenset(contacts),
        hull_points=hull_points,
        fallen=fallen,
    )


def snapshot(
    ms: int,
    robots: tuple[RobotState, ...] = (),
    *,
    ball: tuple[float, float, float] = (0.0, 0.0, 0.07),
    ball_velocity: tuple[float, float, float] = (0.0, 0.0, 0.0),
    toucher: RobotId | None = None,
) -> WorldSnapshot:
    return WorldSnapshot(
        sim_time_ms=ms,
        ball=BallState(position=ball, velocity=ball_velocity),
        robots=robots,
        last_ball_toucher=toucher,
    )
