"""Python client library for robot code: the HLVS robot API and the GameController protocol."""

from __future__ import annotations

from robot.client.errors import (
    BadAddress,
    ConnectFailed,
    ConnectionClosed,
    HandshakeRefused,
    ProtocolViolation,
    ReceiveTimeout,
    RobotClientError,
)
from robot.client.gamecontroller import (
    BadPacket,
    GameControlData,
    GameControllerListener,
    GameControllerReplier,
    GameState,
    PlayerInfo,
    ReturnMessage,
    SecondaryState,
    TeamInfo,
    decode_game_state,
    encode_reply,
)
from robot.client.robot import RobotClient

__all__ = [
    "BadAddress",
    "BadPacket",
    "ConnectFailed",
    "ConnectionClosed",
    "GameControlData",
    "GameControllerListener",
    "GameControllerReplier",
    "GameState",
    "HandshakeRefused",
    "PlayerInfo",
    "ProtocolViolation",
    "ReceiveTimeout",
    "RobotClient",
    "RobotClientError",
    "ReturnMessage",
    "SecondaryState",
    "TeamInfo",
    "decode_game_state",
    "encode_reply",
]
