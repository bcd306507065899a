"""The stub at set plays: it keeps away from the ball at the opponents' and does not kick before
its own is taken; the GameController link tells it whose set play it is, and whose the
protection after it is."""

from __future__ import annotations

import math
import socket
import time

from contracts.gamecontroller import (
    GameControlData,
    GameState,
    RobotInfo,
    SecondaryState,
    TeamInfo,
    encode_game_state,
)
from contracts.geometry import Pose
from robot.stub.behaviour import STAND, Field, GameInfo, Role, decide
from robot.stub.gamestate import GameControllerLink

ADULT = Field(half_length_m=7.0, centre_circle_m=1.5, foot_y_m=0.17, kick_x_m=0.33,
              fast_m_s=0.4, opponent_distance_m=1.5)  # fmt: skip
RED_TEAM, BLUE_TEAM = 7, 9


def _playing(**fields: object) -> GameInfo:
    return GameInfo(phase=GameState.PLAYING, **fields)  # type: ignore[arg-type]


def _striker(game: GameInfo, pose: Pose, ball_field: tuple[float, float]) -> object:
    return decide(role=Role.STRIKER, game=game, pose=pose, ball=pose.to_relative(*ball_field),
                  field=ADULT, searching_s=0.0)  # fmt: skip


def test_at_the_opponents_set_play_it_backs_off_towards_its_own_goal() -> None:
    """A goal kick for the opponents at (6, 2), the striker 0.5 m from the ball facing it: it
    walks away from the ball towards its own goal, and stands (facing the ball) once beyond
    the set-play distance."""
    theirs = _playing(set_play_ours=False, set_play_phase=0, ball_free_in_s=5.0)
    ball = (6.0, 2.0)
    near = Pose(x_m=5.5, y_m=2.0, yaw_rad=0.0)
    action = _striker(theirs, near, ball)
    assert action.kick_foot is None  # type: ignore[attr-defined]
    # heading round to the spot behind it (towards the own goal, -x): it turns first
    assert action.walk != (0.0, 0.0, 0.0)  # type: ignore[attr-defined]
    pose = near
    for _ in range(600):  # the decisions followed exactly, 50 ms apart
        vx, vy, vyaw = _striker(theirs, pose, ball).walk  # type: ignore[attr-defined]
        c, s = math.cos(pose.yaw_rad), math.sin(pose.yaw_rad)
        pose = Pose(x_m=pose.x_m + (vx * c - vy * s) * 0.05,
                    y_m=pose.y_m + (vx * s + vy * c) * 0.05, yaw_rad=pose.yaw_rad + vyaw * 0.05)
    assert math.hypot(pose.x_m - ball[0], pose.y_m - ball[1]) >= ADULT.opponent_distance_m
    assert pose.x_m < ball[0]  # between the ball and its own goal
    far = Pose(x_m=4.0, y_m=2.0, yaw_rad=0.0)  # 2 m away, facing the ball
    assert _striker(theirs, far, ball) == STAND


def test_at_its_own_set_play_it_walks_up_but_lines_up_and_kicks_only_once_it_is_taken() -> None:
    """Touching the ball before its own set play is taken would abort it (and earn a warning):
    in sub-phase 1 the striker walks up to about 0.75 m from the ball and waits."""
    ball = (2.0, 0.0)
    on_the_spot = Pose(x_m=2.0 - ADULT.kick_x_m, y_m=-ADULT.foot_y_m, yaw_rad=0.0)
    playing = _striker(_playing(), on_the_spot, ball)
    assert playing.kick_foot == "left"  # type: ignore[attr-defined]
    for phase in (0, 1, 2):
        ours = _playing(set_play_ours=True, set_play_phase=phase, ball_free_in_s=10.0)
        assert _striker(ours, on_the_spot, ball) == STAND
    behind = Pose(x_m=0.0, y_m=0.0, yaw_rad=0.0)
    positioning = _striker(_playing(set_play_ours=True, set_play_phase=1), behind, ball)
    assert positioning.walk[0] > 0.0  # type: ignore[attr-defined]  # walks to the ball
    near = Pose(x_m=2.0 - 0.6, y_m=0.0, yaw_rad=0.0)  # ... but not into it
    assert _striker(_playing(set_play_ours=True, set_play_phase=1), near, ball) == STAND
    frozen = _striker(_playing(set_play_ours=True, set_play_phase=2), behind, ball)
    assert frozen == STAND
    # taken: the protection that follows is ours, so it plays (its kick-off team or not)
    taken = _playing(our_kick_off=False, restart_ours=True, ball_free_in_s=9.0)
    assert _striker(taken, on_the_spot, ball).kick_foot == "left"  # type: ignore[attr-defined]
    after_theirs = _playing(our_kick_off=True, restart_ours=False, ball_free_in_s=9.0)
    assert _striker(after_theirs, on_the_spot, ball) == STAND


def _rgme(packet: int, state: GameState, secondary: SecondaryState, info: tuple[int, ...],
          secondary_time: int) -> bytes:  # fmt: skip
    players = (RobotInfo(),) * 11
    return encode_game_state(
        GameControlData(
            packet_number=packet,
            players_per_team=4,
            game_type=0,
            state=int(state),
            first_half=True,
            kick_off_team=RED_TEAM,
            secondary_state=int(secondary),
            secondary_state_info=info,
            secs_remaining=300,
            secondary_time=secondary_time,
            teams=(
                TeamInfo(team_number=RED_TEAM, team_colour=1, players=players),
                TeamInfo(team_number=BLUE_TEAM, team_colour=0, players=players),
            ),
        )
    )


def test_the_gamecontroller_link_tells_whose_set_play_and_whose_protection_after_it() -> None:
    """Real RGme packets on loopback UDP: a goal kick for blue, its sub-phases, then taken (the
    secondary state NORMAL again, 10 s of protection): blue's link says ours, red's theirs;
    the next READY forgets it (the kick-off's protection is the kick-off team's)."""
    ports = {}
    for color in ("red", "blue"):
        with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as probe:
            probe.bind(("127.0.0.1", 0))
            ports[color] = probe.getsockname()[1]
    links = {
        color: GameControllerLink(team_color=color, player=1, gamecontroller_ip="127.0.0.1",
                                  data_port=port, return_port=1).start()  # fmt: skip
        for color, port in ports.items()
    }
    sender = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    packets = iter(range(1, 255))

    def seen(packet: bytes) -> dict[str, GameInfo]:
        number = packet[6]  # RGme: header, version (2 bytes), packet number
        deadline = time.monotonic() + 5.0
        while time.monotonic() < deadline:
            for port in ports.values():
                sender.sendto(packet, ("127.0.0.1", port))
            time.sleep(0.02)
            infos = {color: link.info() for color, link in links.items()}
            if all(info is not None for info in infos.values()) and all(
                link._latest is not None and link._latest.packet_number == number
                for link in links.values()
            ):
                return infos  # type: ignore[return-value]
        raise AssertionError("the links did not take the packet")

    try:
        goal_kick = SecondaryState.GOAL_KICK
        for phase in (0, 1, 2):
            info = (BLUE_TEAM, phase, 0, 0)
            infos = seen(_rgme(next(packets), GameState.PLAYING, goal_kick, info, 5))
            assert infos["blue"].set_play_ours is True and infos["red"].set_play_ours is False
            assert infos["blue"].set_play_phase == infos["red"].set_play_phase == phase
        normal, none = SecondaryState.NORMAL, (0, 0, 0, 0)
        infos = seen(_rgme(next(packets), GameState.PLAYING, normal, none, 10))
        assert infos["blue"].set_play_ours is None
        assert infos["blue"].restart_ours is True and infos["red"].restart_ours is False
        assert infos["red"].ball_free_in_s == 10.0
        infos = seen(_rgme(next(packets), GameState.READY, normal, none, 30))
        assert infos["blue"].restart_ours is None and infos["red"].restart_ours is None
    finally:
        sender.close()
        for link in links.values():
            link.close()
