"""Robot side of the GameController protocol: read ``RGme`` v12, send ``RGrt`` v2.

Written from the packet layout (little-endian, packed; 688 bytes), independently of the
referee package, as a robot's own parser would be.
"""

from __future__ import annotations

import socket
import struct
import time
from dataclasses import dataclass
from enum import IntEnum

from robot.client.errors import RobotClientError

GC_DATA_PORT = 3838
GC_RETURN_PORT = 3939
PACKET_SIZE = 688
TEAM_SIZE = 332
ROBOT_INFO_SIZE = 6
MAX_PLAYERS = 11
_HEAD = struct.Struct("<4sHBBBBBBB4sBHhh")  # 24 bytes
_TEAM_HEAD = struct.Struct("<BBBBHB")  # teamNumber, colour, score, penaltyShot, singleShots, seq
_ROBOT = struct.Struct("<BBBBBB")
_PLAYERS_OFFSET = 266


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
    UNKNOWN = 255


class RobotReply(IntEnum):
    MAN_PENALISE = 0
    MAN_UNPENALISE = 1
    ALIVE = 2
    GOALKEEPER = 3
    GAME_INTERRUPTION_READY = 4


class BadPacket(RobotClientError):
    def __init__(self, *, reason: str, size: int) -> None:
        self.reason = reason
        self.size = size
        super().__init__(f"not a RGme v12 packet ({size} bytes): {reason}")


@dataclass(frozen=True, slots=True)
class PlayerInfo:
    penalty: int
    secs_till_unpenalised: int
    warnings: int
    yellow_cards: int
    red_cards: int
    goalkeeper: bool


@dataclass(frozen=True, slots=True)
class TeamInfo:
    team_number: int
    colour: int  # 0 blue, 1 red, ...
    score: int
    players: tuple[PlayerInfo, ...]


@dataclass(frozen=True, slots=True)
class GameControlData:
    packet_number: int
    players_per_team: int
    game_type: int
    state: GameState
    first_half: bool
    kick_off_team: int
    secondary_state: SecondaryState
    secondary_state_info: bytes
    secs_remaining: int
    secondary_time: int
    teams: tuple[TeamInfo, TeamInfo]

    def team(self, team_number: int) -> TeamInfo | None:
        for team in self.teams:
            if team.team_number == team_number:
                return team
        return None

    def score(self, team_number: int) -> int | None:
        team = self.team(team_number)
        return None if team is None else team.score

    def own_penalty(self, team_number: int, player: int) -> int | None:
        """The wire penalty code of player ``player`` (1-based) of ``team_number``; 0 = none."""
        team = self.team(team_number)
        if team is None or not 1 <= player <= len(team.players):
            return None
        return team.players[player - 1].penalty


def decode_game_state(data: bytes) -> GameControlData:
    """Decode one ``RGme`` version 12 packet.

    Raises:
        BadPacket: wrong size, header or version.
    """
    if len(data) != PACKET_SIZE:
        raise BadPacket(reason=f"expected {PACKET_SIZE} bytes", size=len(data))
    (header, version, number, per_team, game_type, state, first_half, kick_off, secondary,
     info, _drop_team, _drop_time, secs, secondary_time) = _HEAD.unpack_from(data)  # fmt: skip
    if header != b"RGme":
        raise BadPacket(reason=f"header {header!r}", size=len(data))
    if version != 12:
        raise BadPacket(reason=f"version {version}", size=len(data))
    try:
        state_value = GameState(state)
    except ValueError as exc:
        raise BadPacket(reason=f"state {state}", size=len(data)) from exc
    try:
        secondary_value = SecondaryState(secondary)
    except ValueError:
        secondary_value = SecondaryState.UNKNOWN
    teams = (_team(data, 24), _team(data, 24 + TEAM_SIZE))
    return GameControlData(
        packet_number=number,
        players_per_team=per_team,
        game_type=game_type,
        state=state_value,
        first_half=bool(first_half),
        kick_off_team=kick_off,
        secondary_state=secondary_value,
        secondary_state_info=bytes(info),
        secs_remaining=secs,
        secondary_time=secondary_time,
        teams=teams,
    )


def _team(data: bytes, offset: int) -> TeamInfo:
    number, colour, score, _shot, _single, _seq = _TEAM_HEAD.unpack_from(data, offset)
    players = tuple(
        PlayerInfo(
            penalty=values[0],
            secs_till_unpenalised=values[1],
            warnings=values[2],
            yellow_cards=values[3],
            red_cards=values[4],
            goalkeeper=bool(values[5]),
        )
        for values in (
            _ROBOT.unpack_from(data, offset + _PLAYERS_OFFSET + i * ROBOT_INFO_SIZE)
            for i in range(MAX_PLAYERS)
        )
    )
    return TeamInfo(team_number=number, colour=colour, score=score, players=players)


def encode_reply(*, team: int, player: int, message: RobotReply = RobotReply.ALIVE) -> bytes:
    """An ``RGrt`` version 2 packet (8 bytes)."""
    return struct.pack("<4sBBBB", b"RGrt", 2, team, player, int(message))


class GameControllerListener:
    """Receives ``RGme`` packets on UDP 3838 and keeps the latest; garbage is counted."""

    def __init__(self, *, host: str = "0.0.0.0", port: int = GC_DATA_PORT) -> None:
        self._sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        self._sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        self._sock.bind((host, port))
        self.latest: GameControlData | None = None
        self.sender: str | None = None  # address of the last GameController packet
        self.bad_packets = 0

    @property
    def port(self) -> int:
        return int(self._sock.getsockname()[1])

    def receive(self, timeout: float | None = None) -> GameControlData | None:
        """Wait up to ``timeout`` s for the next valid packet; None if none came."""
        deadline = None if timeout is None else time.monotonic() + timeout
        while True:
            remaining = None if deadline is None else deadline - time.monotonic()
            if remaining is not None and remaining <= 0:
                return None
            self._sock.settimeout(remaining)
            try:
                data, address = self._sock.recvfrom(4096)
            except TimeoutError:
                return None
            try:
                self.latest = decode_game_state(data)
            except BadPacket:
                self.bad_packets += 1
                continue
            self.sender = address[0]
            return self.latest

    def close(self) -> None:
        self._sock.close()


class GameControllerReplier:
    """Sends ``RGrt`` packets (ALIVE by default) to the GameController on UDP 3939."""

    def __init__(self, *, host: str, team: int, player: int, port: int = GC_RETURN_PORT) -> None:
        self._sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        self._target = (host, port)
        self.team = team
        self.player = player

    def send(self, message: RobotReply = RobotReply.ALIVE) -> None:
        self._sock.sendto(
            encode_reply(team=self.team, player=self.player, message=message), self._target
        )

    def close(self) -> None:
        self._sock.close()
