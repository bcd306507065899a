"""Robot side of the GameController protocol: read ``RGme`` v12, send ``RGrt`` v2.

The packet codec and the wire codes are :mod:`contracts.gamecontroller`'s (the same the referee
sends with); this module gives robot code a view of one packet (its own team found by number,
states as enums) and the UDP listener and replier.
"""

from __future__ import annotations

import os
import socket
import time
from dataclasses import dataclass

from contracts import (
    GC_DATA_PORT,
    GC_RETURN_PORT,
    GameState,
    ProtocolError,
    ReturnData,
    ReturnMessage,
    SecondaryState,
)
from contracts import gamecontroller as wire
from robot.client.errors import RobotClientError


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
        BadPacket: wrong size, header, version or game state.
    """
    try:
        packet = wire.decode_game_state(data)
    except ProtocolError as exc:
        raise BadPacket(reason=exc.reason, size=len(data)) from None
    try:
        state_value = GameState(packet.state)
    except ValueError:
        raise BadPacket(reason=f"state {packet.state}", size=len(data)) from None
    try:
        secondary_value = SecondaryState(packet.secondary_state)
    except ValueError:
        secondary_value = SecondaryState.UNKNOWN
    return GameControlData(
        packet_number=packet.packet_number,
        players_per_team=packet.players_per_team,
        game_type=packet.game_type,
        state=state_value,
        first_half=packet.first_half,
        kick_off_team=packet.kick_off_team,
        secondary_state=secondary_value,
        secondary_state_info=bytes(packet.secondary_state_info),
        secs_remaining=packet.secs_remaining,
        secondary_time=packet.secondary_time,
        teams=(_team(packet.teams[0]), _team(packet.teams[1])),
    )


def _team(team: wire.TeamInfo) -> TeamInfo:
    players = tuple(
        PlayerInfo(
            penalty=robot.penalty,
            secs_till_unpenalised=robot.secs_till_unpenalised,
            warnings=robot.number_of_warnings,
            yellow_cards=robot.yellow_card_count,
            red_cards=robot.red_card_count,
            goalkeeper=robot.goal_keeper,
        )
        for robot in team.players
    )
    return TeamInfo(
        team_number=team.team_number, colour=team.team_colour, score=team.score, players=players
    )


def encode_reply(
    *, team: int, player: int, message: ReturnMessage = ReturnMessage.ALIVE
) -> bytes:
    """An ``RGrt`` version 2 packet (8 bytes)."""
    return wire.encode_return(ReturnData(team=team, player=player, message=message))


GAMECONTROLLER_ENV = "ROBOCUP_GAMECONTROLLER_IP"


class GameControllerListener:
    """Receives ``RGme`` packets on UDP 3838 and keeps the latest; garbage is counted.

    Only packets from the GameController are taken: ``gamecontroller`` (an address or a host
    name; default: ``$ROBOCUP_GAMECONTROLLER_IP``, which the runner gives every robot). A packet
    from any other address (a teammate, the other team) is ignored and counted in
    ``foreign_packets``, its sender kept in ``foreign_sender``. With neither the argument nor the
    variable (a robot outside a match), packets from any address are taken.
    """

    def __init__(self, *, host: str = "0.0.0.0", port: int = GC_DATA_PORT,
                 gamecontroller: str | None = None) -> None:
        self._sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        self._sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        self._sock.bind((host, port))
        name = gamecontroller if gamecontroller is not None else os.environ.get(
            GAMECONTROLLER_ENV, "")
        self.allowed: frozenset[str] | None = _addresses(name.strip()) if name.strip() else None
        self.latest: GameControlData | None = None
        self.sender: str | None = None  # address of the last GameController packet
        self.bad_packets = 0
        self.foreign_packets = 0  # packets from another address than the GameController's
        self.foreign_sender: str | None = None

    @property
    def port(self) -> int:
        return int(self._sock.getsockname()[1])

    def receive(self, timeout: float | None = None) -> GameControlData | None:
        """Wait up to ``timeout`` s for the next valid packet from the GameController; None if
        none came."""
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
            if self.allowed is not None and address[0] not in self.allowed:
                self.foreign_packets += 1
                self.foreign_sender = address[0]
                continue
            try:
                self.latest = decode_game_state(data)
            except BadPacket:
                self.bad_packets += 1
                continue
            self.sender = address[0]
            return self.latest

    def close(self) -> None:
        self._sock.close()


def _addresses(name: str) -> frozenset[str]:
    """The IPv4 addresses of ``name`` (itself when it is one, or cannot be resolved)."""
    try:
        found = socket.getaddrinfo(name, None, socket.AF_INET, socket.SOCK_DGRAM)
    except OSError:
        return frozenset({name})
    return frozenset({str(info[4][0]) for info in found} | {name})


class GameControllerReplier:
    """Sends ``RGrt`` packets (ALIVE by default) to the GameController on UDP 3939."""

    def __init__(self, *, host: str, team: int, player: int, port: int = GC_RETURN_PORT) -> None:
        self._sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        self._target = (host, port)
        self.team = team
        self.player = player

    def send(self, message: ReturnMessage = ReturnMessage.ALIVE) -> None:
        self._sock.sendto(
            encode_reply(team=self.team, player=self.player, message=message), self._target
        )

    def close(self) -> None:
        self._sock.close()


__all__ = [
    "GC_DATA_PORT",
    "GC_RETURN_PORT",
    "GAMECONTROLLER_ENV",
    "BadPacket",
    "GameControlData",
    "GameControllerListener",
    "GameControllerReplier",
    "GameState",
    "PlayerInfo",
    "ReturnMessage",
    "SecondaryState",
    "TeamInfo",
    "decode_game_state",
    "encode_reply",
]
