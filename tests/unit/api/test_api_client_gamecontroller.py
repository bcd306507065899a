"""The robot-side RGme parser and RGrt sender, against packets built by hand with struct."""

from __future__ import annotations

import socket
import struct

import pytest

from robot.client import (
    BadPacket,
    GameControllerListener,
    GameControllerReplier,
    GameState,
    ReturnMessage,
    SecondaryState,
    decode_game_state,
    encode_reply,
)


def _team(number: int, colour: int, score: int, penalties: dict[int, tuple[int, int]]) -> bytes:
    head = struct.pack("<BBBBHB", number, colour, score, 0, 0, 0) + bytes(253)
    coach = bytes(6)
    players = b"".join(
        struct.pack("<BBBBBB", *penalties.get(n, (0, 0)), 0, 0, 0, 1 if n == 1 else 0)
        for n in range(1, 12)
    )
    team = head + coach + players
    assert len(team) == 332
    return team


def _packet(*, state: int = 3, secondary: int = 4, secs: int = -5) -> bytes:
    head = b"RGme" + struct.pack("<HBBBBBBB", 12, 7, 4, 0, state, 1, 8, secondary)
    head += bytes((25, 1, 0, 0)) + struct.pack("<BHhh", 0, 0xFFFF, secs, 12)
    assert len(head) == 24
    return head + _team(25, 0, 2, {}) + _team(8, 1, 3, {2: (34, 17)})


def test_decodes_the_fields_a_robot_needs() -> None:
    data = decode_game_state(_packet())
    assert data.state is GameState.PLAYING
    assert data.secondary_state is SecondaryState.DIRECT_FREEKICK
    assert data.secondary_state_info == bytes((25, 1, 0, 0))
    assert data.first_half and data.kick_off_team == 8 and data.packet_number == 7
    assert data.secs_remaining == -5 and data.secondary_time == 12
    assert data.score(8) == 3 and data.score(25) == 2 and data.score(99) is None
    assert data.own_penalty(8, 2) == 34 and data.own_penalty(8, 1) == 0
    assert data.team(8) is not None and data.team(8).players[1].secs_till_unpenalised == 17  # type: ignore[union-attr]
    assert data.team(25).players[0].goalkeeper  # type: ignore[union-attr]


@pytest.mark.parametrize(
    "packet",
    [
        b"RGme",
        b"XXXX" + _packet()[4:],
        _packet()[:4] + b"\x0b\x00" + _packet()[6:],
        _packet() + b"x",
    ],
)
def test_bad_packets_are_typed_errors(packet: bytes) -> None:
    with pytest.raises(BadPacket):
        decode_game_state(packet)


def test_reply_layout() -> None:
    assert encode_reply(team=8, player=3) == b"RGrt\x02\x08\x03\x02"
    assert encode_reply(team=8, player=1, message=ReturnMessage.GOALKEEPER)[-1] == 3


def test_listener_and_replier_over_loopback_udp() -> None:
    listener = GameControllerListener(host="127.0.0.1", port=0)
    gc = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    gc.bind(("127.0.0.1", 0))
    gc.settimeout(5)
    try:
        gc.sendto(b"garbage", ("127.0.0.1", listener.port))
        gc.sendto(_packet(state=1), ("127.0.0.1", listener.port))
        data = listener.receive(timeout=5)
        assert data is not None and data.state is GameState.READY
        assert listener.bad_packets == 1 and listener.sender == "127.0.0.1"
        replier = GameControllerReplier(
            host="127.0.0.1", team=8, player=2, port=gc.getsockname()[1]
        )
        replier.send()
        assert gc.recvfrom(64)[0] == b"RGrt\x02\x08\x02\x02"
        replier.close()
        assert listener.receive(timeout=0.05) is None
    finally:
        gc.close()
        listener.close()


def test_reads_the_referee_packets() -> None:
    from referee.autoref import Referee
    from simulator.match_setup import referee_config
    from tests.integration.api.match_specs import short_spec

    with Referee(config=referee_config(short_spec(players=2))) as referee:
        data = decode_game_state(referee.packet())
    assert data.state is GameState.INITIAL
    assert {team.team_number for team in data.teams} == {8, 25}
    assert data.score(8) == 0 and data.own_penalty(25, 2) == 0
    assert data.team(8).players[0].goalkeeper  # type: ignore[union-attr]


def test_listener_takes_packets_from_the_gamecontroller_only() -> None:
    """A teammate (another address) forging a packet is ignored and counted; the
    GameController's packets are taken."""
    listener = GameControllerListener(host="0.0.0.0", port=0, gamecontroller="127.0.0.2")
    teammate = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    teammate.bind(("127.0.0.1", 0))
    gc = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    gc.bind(("127.0.0.2", 0))
    try:
        teammate.sendto(_packet(state=3), ("127.0.0.1", listener.port))  # a forged PLAYING
        assert listener.receive(timeout=0.3) is None
        assert listener.foreign_packets == 1 and listener.foreign_sender == "127.0.0.1"
        assert listener.latest is None
        gc.sendto(_packet(state=1), ("127.0.0.1", listener.port))
        data = listener.receive(timeout=5)
        assert data is not None and data.state is GameState.READY
        assert listener.sender == "127.0.0.2" and listener.foreign_packets == 1
    finally:
        teammate.close()
        gc.close()
        listener.close()


def test_listener_address_comes_from_the_environment(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("ROBOCUP_GAMECONTROLLER_IP", "localhost")
    listener = GameControllerListener(host="127.0.0.1", port=0)
    try:
        assert listener.allowed is not None and "127.0.0.1" in listener.allowed
    finally:
        listener.close()
    monkeypatch.delenv("ROBOCUP_GAMECONTROLLER_IP")
    anyone = GameControllerListener(host="127.0.0.1", port=0)
    try:
        assert anyone.allowed is None  # outside a match: no address to hold packets to
    finally:
        anyone.close()
