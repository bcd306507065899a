"""The GameController protocol: ``RGme`` version 12 (688 bytes) and ``RGrt`` version 2 (8 bytes).

The one codec and the one set of wire codes for the referee (which sends ``RGme`` and reads
``RGrt``) and robot code (:mod:`robot.client.gamecontroller`, which does the opposite).

Little-endian, packed, layout of ``RoboCupGameControlData.h``: a 24-byte header, then two
332-byte TeamInfo blocks (teams[0] the team playing on the left, teams[1] the other), each with
a coach and 11 players of 6-byte RobotInfo.

As the league's GameController (``controller/net/Sender.java``) sends it: one ``RGme`` at a
fixed rate (every 500 ms, every 50 ms in a game not paced to real time: :func:`send_period_s`),
never an extra one on a state change, ``packetNumber`` + 1 per packet sent (mod 256,
:func:`with_packet_number` stamps it at sending).
"""

from __future__ import annotations

import struct
from dataclasses import dataclass, field
from enum import IntEnum

from contracts.errors import ProtocolError

GC_DATA_PORT = 3838  # RGme, GameController -> robots (UDP)
GC_RETURN_PORT = 3939  # RGrt, robots -> GameController (UDP)
GAME_HEADER = b"RGme"
GAME_VERSION = 12
RETURN_HEADER = b"RGrt"
RETURN_VERSION = 2
MAX_PLAYERS = 11
DROP_IN_TIME_NONE = 0xFFFF
SEND_PERIOD_S = 0.5  # Sender.java:63, UPDATEFREQUENCY 500 ms
FAST_SEND_PERIOD_S = 0.05  # GameControllerSimulator.java:386-387, --fast: 50 ms


def send_period_s(maximum_real_time_factor: float) -> float:
    """Wall seconds between two ``RGme`` packets in a game with this real-time factor limit:
    the league's referee starts its GameController with ``--fast`` when the game is not paced
    to real time (``maximum_real_time_factor`` <= 0, as fast as possible, or above 1;
    hlvs_webots ``referee.py:1949-1950``), which then sends every 50 ms."""
    fast = maximum_real_time_factor <= 0.0 or maximum_real_time_factor > 1.0
    return FAST_SEND_PERIOD_S if fast else SEND_PERIOD_S

_HEADER = struct.Struct("<4sH7B4sBHhh")  # 24 bytes
_TEAM = struct.Struct("<BBBBHB253s")  # 260 bytes, then coach + 11 players
_ROBOT = struct.Struct("<6B")
_RETURN = struct.Struct("<4sBBBB")
TEAM_SIZE = _TEAM.size + (MAX_PLAYERS + 1) * _ROBOT.size  # 332
GAME_SIZE = _HEADER.size + 2 * TEAM_SIZE  # 688


class GameState(IntEnum):
    INITIAL = 0
    READY = 1
    SET = 2
    PLAYING = 3
    FINISHED = 4


class SecondaryState(IntEnum):
    NORMAL = 0
    PENALTYSHOOT = 1
    OVERTIME = 2
    TIMEOUT = 3
    DIRECT_FREEKICK = 4
    INDIRECT_FREEKICK = 5
    PENALTYKICK = 6
    CORNER_KICK = 7
    GOAL_KICK = 8
    THROW_IN = 9
    UNKNOWN = 255  # robot side: a code this build does not know (never sent)

    @property
    def is_set_play(self) -> bool:
        return SecondaryState.DIRECT_FREEKICK <= self <= SecondaryState.THROW_IN


class Penalty(IntEnum):
    """Penalty codes on the wire (GameController ``Penalties.java``)."""

    NONE = 0
    SUBSTITUTE = 14
    MANUAL = 15
    BALL_MANIPULATION = 30
    PHYSICAL_CONTACT = 31
    ILLEGAL_ATTACK = 32
    ILLEGAL_DEFENSE = 33
    PICKUP_OR_INCAPABLE = 34
    SERVICE = 35


class GameTypeCode(IntEnum):
    ROUNDROBIN = 0
    PLAYOFF = 1
    DROPIN = 2


class TeamColourCode(IntEnum):
    BLUE = 0
    RED = 1


DROPBALL_TEAM = 128  # kickOffTeam after a dropped ball


@dataclass(frozen=True, slots=True)
class RobotInfo:
    penalty: int = 0
    secs_till_unpenalised: int = 0
    number_of_warnings: int = 0
    yellow_card_count: int = 0
    red_card_count: int = 0
    goal_keeper: bool = False


@dataclass(frozen=True, slots=True, kw_only=True)
class TeamInfo:
    team_number: int
    team_colour: int  # 0 BLUE, 1 RED
    score: int = 0
    penalty_shot: int = 0
    single_shots: int = 0
    coach_sequence: int = 0
    coach_message: bytes = b""
    coach: RobotInfo = RobotInfo()
    players: tuple[RobotInfo, ...] = field(default_factory=lambda: (RobotInfo(),) * MAX_PLAYERS)


@dataclass(frozen=True, slots=True, kw_only=True)
class GameControlData:
    packet_number: int
    players_per_team: int
    game_type: int
    state: int
    first_half: bool
    kick_off_team: int
    secondary_state: int
    secondary_state_info: tuple[int, int, int, int]
    secs_remaining: int
    secondary_time: int
    teams: tuple[TeamInfo, TeamInfo]
    drop_in_team: int = 0
    drop_in_time: int = DROP_IN_TIME_NONE
    version: int = GAME_VERSION


class ReturnMessage(IntEnum):
    MAN_PENALISE = 0
    MAN_UNPENALISE = 1
    ALIVE = 2
    GOALKEEPER = 3
    GAME_INTERRUPTION_READY = 4


@dataclass(frozen=True, slots=True)
class ReturnData:
    team: int
    player: int  # 1-based
    message: ReturnMessage
    version: int = RETURN_VERSION


def _robot_bytes(robot: RobotInfo) -> bytes:
    return _ROBOT.pack(
        robot.penalty,
        robot.secs_till_unpenalised,
        robot.number_of_warnings,
        robot.yellow_card_count,
        robot.red_card_count,
        int(robot.goal_keeper),
    )


def _team_bytes(team: TeamInfo) -> bytes:
    if len(team.players) > MAX_PLAYERS:
        raise ValueError(f"at most {MAX_PLAYERS} players per team, got {len(team.players)}")
    players = tuple(team.players) + (RobotInfo(),) * (MAX_PLAYERS - len(team.players))
    head = _TEAM.pack(
        team.team_number,
        team.team_colour,
        team.score,
        team.penalty_shot,
        team.single_shots,
        team.coach_sequence,
        team.coach_message[:253],
    )
    return head + _robot_bytes(team.coach) + b"".join(_robot_bytes(p) for p in players)


def encode_game_state(data: GameControlData) -> bytes:
    """Pack one ``RGme`` datagram (688 bytes)."""
    head = _HEADER.pack(
        GAME_HEADER,
        data.version,
        data.packet_number & 0xFF,
        data.players_per_team,
        data.game_type,
        data.state,
        int(data.first_half),
        data.kick_off_team,
        data.secondary_state,
        bytes(data.secondary_state_info),
        data.drop_in_team,
        data.drop_in_time,
        data.secs_remaining,
        data.secondary_time,
    )
    return head + _team_bytes(data.teams[0]) + _team_bytes(data.teams[1])


PACKET_NUMBER_OFFSET = 6  # after the header "RGme" and the u16 version


def with_packet_number(raw: bytes, number: int) -> bytes:
    """``raw`` (an encoded ``RGme`` datagram) with its ``packetNumber`` set to ``number`` (mod
    256): the sender numbers the packets as it sends them, as the league's ``Sender`` does."""
    return raw[:PACKET_NUMBER_OFFSET] + bytes((number & 0xFF,)) + raw[PACKET_NUMBER_OFFSET + 1 :]


def _decode_team(raw: bytes) -> TeamInfo:
    number, colour, score, shot, singles, seq, message = _TEAM.unpack_from(raw, 0)
    robots = [
        RobotInfo(values[0], values[1], values[2], values[3], values[4], bool(values[5]))
        for values in (
            _ROBOT.unpack_from(raw, _TEAM.size + i * _ROBOT.size) for i in range(MAX_PLAYERS + 1)
        )
    ]
    return TeamInfo(
        team_number=number,
        team_colour=colour,
        score=score,
        penalty_shot=shot,
        single_shots=singles,
        coach_sequence=seq,
        coach_message=message.rstrip(b"\0"),
        coach=robots[0],
        players=tuple(robots[1:]),
    )


def decode_game_state(raw: bytes, *, peer: str = "<bytes>") -> GameControlData:
    if len(raw) != GAME_SIZE:
        raise ProtocolError(peer=peer, reason=f"RGme must be {GAME_SIZE} bytes", size=len(raw))
    values = _HEADER.unpack_from(raw, 0)
    if values[0] != GAME_HEADER:
        raise ProtocolError(peer=peer, reason=f"header {values[0]!r}, expected b'RGme'")
    if values[1] != GAME_VERSION:
        raise ProtocolError(peer=peer, reason=f"RGme version {values[1]}, expected {GAME_VERSION}")
    info = values[9]
    return GameControlData(
        version=values[1],
        packet_number=values[2],
        players_per_team=values[3],
        game_type=values[4],
        state=values[5],
        first_half=bool(values[6]),
        kick_off_team=values[7],
        secondary_state=values[8],
        secondary_state_info=(info[0], info[1], info[2], info[3]),
        drop_in_team=values[10],
        drop_in_time=values[11],
        secs_remaining=values[12],
        secondary_time=values[13],
        teams=(
            _decode_team(raw[_HEADER.size : _HEADER.size + TEAM_SIZE]),
            _decode_team(raw[_HEADER.size + TEAM_SIZE :]),
        ),
    )


def encode_return(data: ReturnData) -> bytes:
    return _RETURN.pack(RETURN_HEADER, data.version, data.team, data.player, int(data.message))


def decode_return(raw: bytes, *, peer: str = "<bytes>") -> ReturnData:
    if len(raw) != _RETURN.size:
        raise ProtocolError(peer=peer, reason=f"RGrt must be {_RETURN.size} bytes", size=len(raw))
    header, version, team, player, message = _RETURN.unpack(raw)
    if header != RETURN_HEADER:
        raise ProtocolError(peer=peer, reason=f"header {header!r}, expected b'RGrt'")
    if version != RETURN_VERSION:
        raise ProtocolError(peer=peer, reason=f"RGrt version {version}, expected {RETURN_VERSION}")
    if player < 1 or player > MAX_PLAYERS:
        raise ProtocolError(peer=peer, reason=f"player {player}, expected 1..{MAX_PLAYERS}")
    try:
        kind = ReturnMessage(message)
    except ValueError as exc:
        raise ProtocolError(peer=peer, reason=f"message {message}, expected 0..4") from exc
    return ReturnData(team=team, player=player, message=kind, version=version)
