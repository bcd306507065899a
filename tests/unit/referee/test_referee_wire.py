"""RGme v12 / RGrt v2 bytes, pinned against a layout built by hand with struct."""

from __future__ import annotations

import struct

import pytest

from contracts.gamecontroller import (
    GameControlData,
    ReturnData,
    ReturnMessage,
    RobotInfo,
    TeamInfo,
    decode_game_state,
    decode_return,
    encode_game_state,
    encode_return,
)
from contracts.ids import RobotId, TeamColor
from contracts.match_spec import GameType
from referee import ProtocolError
from referee.config import TimingConfig
from referee.gamecontroller import GameController, GameState, Penalty, SecondaryState
from referee.gamecontroller.packet import game_control_data


def _expected_bytes() -> bytes:
    """A known state, laid out field by field from RoboCupGameControlData.h (v12)."""
    header = (
        b"RGme"
        + struct.pack("<H", 12)
        # packet 7, 4 players, ROUNDROBIN, PLAYING, first half, kick-off team 25, THROW_IN
        + bytes([7, 4, 0, 3, 1, 25, 9])
        + bytes([8, 1, 0, 0])  # secondaryStateInfo: team 8, sub-phase 1
        + bytes([0])  # dropInTeam
        + struct.pack("<H", 0xFFFF)  # dropInTime
        + struct.pack("<h", 512)  # secsRemaining
        + struct.pack("<h", -3)  # secondaryTime
    )
    assert len(header) == 24

    def team(number: int, colour: int, score: int, players: list[bytes]) -> bytes:
        head = bytes([number, colour, score, 0]) + struct.pack("<H", 0) + bytes([0]) + bytes(253)
        coach = bytes(6)
        body = b"".join(players) + bytes(6) * (11 - len(players))
        block = head + coach + body
        assert len(block) == 332
        return block

    blue = team(25, 0, 2, [bytes([0, 0, 0, 0, 0, 1]), bytes([34, 7, 1, 0, 0, 0])])
    red = team(8, 1, 1, [bytes([0, 0, 0, 1, 0, 1]), bytes([0, 0, 0, 0, 0, 0])])
    return header + blue + red


def _known_state() -> GameControlData:
    return GameControlData(
        packet_number=7,
        players_per_team=4,
        game_type=0,
        state=3,
        first_half=True,
        kick_off_team=25,
        secondary_state=9,
        secondary_state_info=(8, 1, 0, 0),
        secs_remaining=512,
        secondary_time=-3,
        teams=(
            TeamInfo(
                team_number=25, team_colour=0, score=2,
                players=(RobotInfo(goal_keeper=True), RobotInfo(34, 7, 1, 0, 0, False)),
            ),
            TeamInfo(
                team_number=8, team_colour=1, score=1,
                players=(RobotInfo(yellow_card_count=1, goal_keeper=True), RobotInfo()),
            ),
        ),
    )


def test_rgme_bytes_are_pinned() -> None:
    raw = encode_game_state(_known_state())
    assert len(raw) == 688
    assert raw == _expected_bytes()


def test_rgme_decodes_back() -> None:
    decoded = decode_game_state(_expected_bytes())
    assert decoded.secs_remaining == 512 and decoded.secondary_time == -3
    assert decoded.teams[0].team_number == 25 and decoded.teams[1].team_colour == 1
    assert decoded.teams[0].players[1] == RobotInfo(34, 7, 1, 0, 0, False)
    assert decoded.drop_in_time == 0xFFFF
    assert encode_game_state(decoded) == _expected_bytes()


@pytest.mark.parametrize(
    ("raw", "reason"),
    [
        (b"RGme" + bytes(10), "688 bytes"),
        (b"XXXX" + _expected_bytes()[4:], "header"),
        (_expected_bytes()[:4] + struct.pack("<H", 11) + _expected_bytes()[6:], "version 11"),
    ],
)
def test_rgme_rejects_bad_datagrams(raw: bytes, reason: str) -> None:
    with pytest.raises(ProtocolError) as info:
        decode_game_state(raw, peer="10.0.0.9:3838")
    assert reason in str(info.value) and info.value.peer == "10.0.0.9:3838"


def test_rgrt_bytes_and_codes() -> None:
    raw = encode_return(ReturnData(team=25, player=3, message=ReturnMessage.GOALKEEPER))
    assert raw == b"RGrt" + bytes([2, 25, 3, 3])
    assert decode_return(b"RGrt\x02\x08\x01\x02") == ReturnData(8, 1, ReturnMessage.ALIVE)
    assert [m.value for m in ReturnMessage] == [0, 1, 2, 3, 4]


@pytest.mark.parametrize(
    "raw",
    [b"RGrt\x02\x08\x01", b"RGrt\x01\x08\x01\x02", b"RGxx\x02\x08\x01\x02", b"RGrt\x02\x08\x01\x09",
     b"RGrt\x02\x08\x00\x02"],
)
def test_rgrt_rejects_garbage(raw: bytes) -> None:
    with pytest.raises(ProtocolError):
        decode_return(raw, peer="robot")


def test_packet_from_gamecontroller_puts_the_left_team_first_and_set_play_info() -> None:
    gc = GameController(
        game_type=GameType.KNOCKOUT, players={TeamColor.RED: (1, 2), TeamColor.BLUE: (1, 2)},
        kickoff=TeamColor.RED, timing=TimingConfig(),
    )
    gc.transition(GameState.READY)
    gc.transition(GameState.SET)
    gc.transition(GameState.PLAYING)
    gc.penalize(RobotId(TeamColor.BLUE, 2), Penalty.PICKUP_OR_INCAPABLE, 9.2)
    gc.begin_set_play(SecondaryState.CORNER_KICK, TeamColor.RED)
    data = game_control_data(
        gc, team_numbers={TeamColor.RED: 8, TeamColor.BLUE: 25}, players_per_team=4,
        packet_number=300, left_team=TeamColor.BLUE,
    )
    raw = encode_game_state(data)
    assert raw[6] == 300 & 0xFF and raw[8] == 1  # PLAYOFF
    assert raw[9] == 3 and raw[11] == 8 and raw[12] == 7  # PLAYING, kick-off red (8), CORNER_KICK
    assert raw[13:17] == bytes([8, 0, 0, 0])
    blue, red = raw[24:356], raw[356:688]
    assert blue[0] == 25 and blue[1] == 0 and red[0] == 8 and red[1] == 1
    assert blue[266 + 6 : 266 + 12] == bytes([34, 10, 0, 0, 0, 0])  # player 2: INCAPABLE, 10 s
    assert red[266 + 5] == 1  # player 1 is the goalkeeper


def test_dropped_ball_kickoff_team_is_128() -> None:
    gc = GameController(
        game_type=GameType.NORMAL, players={TeamColor.RED: (1,), TeamColor.BLUE: (1,)},
        kickoff=TeamColor.BLUE, timing=TimingConfig(),
    )
    for state in (GameState.READY, GameState.SET, GameState.PLAYING):
        gc.transition(state)
    gc.dropped_ball()
    data = game_control_data(
        gc, team_numbers={TeamColor.RED: 8, TeamColor.BLUE: 25}, players_per_team=4,
        packet_number=1, left_team=TeamColor.RED,
    )
    assert data.kick_off_team == 128 and data.state == 1 and data.secondary_time == 45
